/* Flat-shaded meshes by the painter's algorithm: enough for a few thousand
 * faces of one body, with no OpenGL context on a headless machine. */
#include "views/render.h"

#include <cairo.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

#include "tcb/fsutil.h"
#include "views/colormap.h"

enum { PANEL = 360, TITLE = 34, BAR = 46 };
static const char *const FONT = "DejaVu Sans";

typedef struct camera {
    int right, up, view;    /* coordinate axes */
    double cx, cy, scale;   /* screen = (PANEL/2 + scale (x − cx), …) */
} camera;

typedef struct face_depth {
    double depth;
    int face;
} face_depth;

static int by_depth(const void *a, const void *b)
{
    double da = ((const face_depth *)a)->depth, db = ((const face_depth *)b)->depth;
    return (da > db) - (da < db);
}

static camera make_camera(const tcb_render_panel *panels, int n_panels, int nv, const float *ref,
                          int n_ref)
{
    double lo[3] = {DBL_MAX, DBL_MAX, DBL_MAX}, hi[3] = {-DBL_MAX, -DBL_MAX, -DBL_MAX};
    for (int k = 0; k < n_ref; k++)
        for (int a = 0; a < 3; a++) {
            lo[a] = fmin(lo[a], ref[3 * (size_t)k + a]);
            hi[a] = fmax(hi[a], ref[3 * (size_t)k + a]);
        }
    camera c = {0};
    for (int a = 1; a < 3; a++)
        if (hi[a] - lo[a] < hi[c.view] - lo[c.view]) c.view = a;
    c.up = c.view == 1 ? 2 : 1;
    c.right = 3 - c.view - c.up;
    double x0 = DBL_MAX, x1 = -DBL_MAX, y0 = DBL_MAX, y1 = -DBL_MAX;
    for (int p = 0; p < n_panels; p++)
        for (int k = 0; k < nv; k++) {
            const float *v = panels[p].verts + 3 * (size_t)k;
            x0 = fmin(x0, v[c.right]), x1 = fmax(x1, v[c.right]);
            y0 = fmin(y0, v[c.up]), y1 = fmax(y1, v[c.up]);
        }
    c.cx = 0.5 * (x0 + x1), c.cy = 0.5 * (y0 + y1);
    c.scale = 0.9 * PANEL / fmax(fmax(x1 - x0, y1 - y0), 1e-12);
    return c;
}

static void project(const camera *c, const float *v, double *x, double *y)
{
    *x = PANEL / 2.0 + c->scale * (v[c->right] - c->cx);
    *y = PANEL / 2.0 - c->scale * (v[c->up] - c->cy);
}

/* |cos| of the face's slant to the viewing direction: 1 facing the viewer. */
static double facing(const camera *c, const float *a, const float *b, const float *d)
{
    double u[3], w[3], n[3];
    for (int k = 0; k < 3; k++) u[k] = b[k] - a[k], w[k] = d[k] - a[k];
    n[0] = u[1] * w[2] - u[2] * w[1], n[1] = u[2] * w[0] - u[0] * w[2], n[2] = u[0] * w[1] - u[1] * w[0];
    double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    return len > 0 ? fabs(n[c->view]) / len : 0;
}

static void draw_mesh(cairo_t *cr, const camera *c, const tcb_render_panel *p,
                      const int32_t *faces, int nf, face_depth *order)
{
    for (int f = 0; f < nf; f++) {
        const int32_t *t = faces + 3 * (size_t)f;
        order[f] = (face_depth){p->verts[3 * (size_t)t[0] + c->view] +
                                    p->verts[3 * (size_t)t[1] + c->view] +
                                    p->verts[3 * (size_t)t[2] + c->view],
                                f};
    }
    /* The viewer sits on the +view side: far faces (small depth) first. */
    qsort(order, (size_t)nf, sizeof *order, by_depth);
    cairo_set_line_width(cr, 0.7); /* the stroke closes seams between fills */
    cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
    for (int o = 0; o < nf; o++) {
        const int32_t *t = faces + 3 * (size_t)order[o].face;
        const float *v[3];
        double rgb[3] = {0, 0, 0};
        for (int k = 0; k < 3; k++) {
            v[k] = p->verts + 3 * (size_t)t[k];
            for (int a = 0; a < 3 && !p->face_rgb; a++) rgb[a] += p->rgb[3 * (size_t)t[k] + a] / (3 * 255.0);
        }
        for (int a = 0; a < 3 && p->face_rgb; a++) rgb[a] = p->face_rgb[3 * (size_t)order[o].face + a] / 255.0;
        double shade = 0.45 + 0.55 * facing(c, v[0], v[1], v[2]);
        cairo_set_source_rgb(cr, shade * rgb[0], shade * rgb[1], shade * rgb[2]);
        for (int k = 0; k < 3; k++) {
            double x, y;
            project(c, v[k], &x, &y);
            if (k) cairo_line_to(cr, x, y);
            else cairo_move_to(cr, x, y);
        }
        cairo_close_path(cr);
        cairo_fill_preserve(cr);
        cairo_stroke(cr);
    }
}

/* A sequence of points alone (no faces): each vertex a dot in its colour,
 * far ones first. */
static void draw_points(cairo_t *cr, const camera *c, const tcb_render_panel *p, int nv, face_depth *order)
{
    for (int v = 0; v < nv; v++) order[v] = (face_depth){p->verts[3 * (size_t)v + c->view], v};
    qsort(order, (size_t)nv, sizeof *order, by_depth);
    for (int o = 0; o < nv; o++) {
        const uint8_t *rgb = p->rgb + 3 * (size_t)order[o].face;
        double x, y;
        project(c, p->verts + 3 * (size_t)order[o].face, &x, &y);
        cairo_set_source_rgb(cr, rgb[0] / 255.0, rgb[1] / 255.0, rgb[2] / 255.0);
        cairo_arc(cr, x, y, 1.4, 0, 2 * M_PI);
        cairo_fill(cr);
    }
}

static void draw_colorbar(cairo_t *cr, double max)
{
    const double x0 = 40, x1 = PANEL - 40, y = PANEL + 8, h = 12;
    for (int k = 0; k < (int)(x1 - x0); k++) {
        uint8_t rgb[3];
        tcb_color_by_error(k / (x1 - x0 - 1), 1, rgb);
        cairo_set_source_rgb(cr, rgb[0] / 255.0, rgb[1] / 255.0, rgb[2] / 255.0);
        cairo_rectangle(cr, x0 + k, y, 1, h);
        cairo_fill(cr);
    }
    char label[64];
    cairo_set_source_rgb(cr, 0.15, 0.15, 0.15);
    cairo_set_font_size(cr, 12);
    cairo_move_to(cr, x0, y + h + 14);
    cairo_show_text(cr, "0");
    snprintf(label, sizeof label, "%.3f and more", max);
    cairo_text_extents_t e;
    cairo_text_extents(cr, label, &e);
    cairo_move_to(cr, x1 - e.x_advance, y + h + 14);
    cairo_show_text(cr, label);
}

int tcb_render_panels(const char *path, const tcb_render_panel *panels, int n_panels, int nv,
                      const int32_t *faces, int nf, const float *ref, int n_ref, double colorbar_max,
                      tcb_error *err)
{
    size_t n_order = (size_t)(nf > 0 ? nf : nv > 0 ? nv : 1);
    face_depth *order = malloc(n_order * sizeof *order);
    if (!order) return tcb_fail(err, TCB_ERR_NOMEM, "out of memory for %d faces", nf);
    camera c = make_camera(panels, n_panels, nv, ref, n_ref);
    cairo_surface_t *surface =
        cairo_image_surface_create(CAIRO_FORMAT_RGB24, PANEL * n_panels, TITLE + PANEL + BAR);
    cairo_t *cr = cairo_create(surface);
    cairo_set_source_rgb(cr, 1, 1, 1);
    cairo_paint(cr);
    cairo_select_font_face(cr, FONT, CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
    for (int p = 0; p < n_panels; p++) {
        cairo_save(cr);
        cairo_translate(cr, p * PANEL, 0);
        cairo_set_source_rgb(cr, 0.15, 0.15, 0.15);
        cairo_set_font_size(cr, 15);
        cairo_move_to(cr, 12, 22);
        cairo_show_text(cr, panels[p].title);
        cairo_translate(cr, 0, TITLE);
        if (nf > 0) draw_mesh(cr, &c, &panels[p], faces, nf, order);
        else draw_points(cr, &c, &panels[p], nv, order);
        if (colorbar_max > 0 && p == n_panels - 1) draw_colorbar(cr, colorbar_max);
        cairo_restore(cr);
    }
    free(order);
    cairo_destroy(cr);
    return tcb_render_save_png(surface, path, err);
}

int tcb_render_save_png(cairo_surface_t *surface, const char *path, tcb_error *err)
{
    char tmp[TCB_PATH_MAX];
    int rc = tcb_temp_path_for(path, tmp, sizeof tmp, err);
    cairo_status_t st = cairo_surface_status(surface);
    if (!rc && st == CAIRO_STATUS_SUCCESS) st = cairo_surface_write_to_png(surface, tmp);
    cairo_surface_destroy(surface);
    if (rc) return rc;
    if (st != CAIRO_STATUS_SUCCESS) {
        unlink(tmp);
        return tcb_fail(err, TCB_ERR_IO, "%s: %s", path, cairo_status_to_string(st));
    }
    return tcb_publish(tmp, path, err);
}
