/* `tcbench frames` for a method with `surface`: its reconstruction of each
 * frame with one checkerboard in UV space, or, for a mesh without charts,
 * each vertex in the colour of its place in the first frame drawn
 * (tcb/frames.h). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scoring/scoring.h"
#include "tcb/frames.h"
#include "tcb/fsutil.h"
#include "tcb/geometry.h"
#include "tcb/mesh_io.h"
#include "views/checker.h"
#include "views/colormap.h"
#include "views/frames_style.h"
#include "views/render.h"

/* More charts would make the texture larger than viewers like (16 x 16
 * cells of 256 pixels: 4096 pixels a side). */
#define MAX_CHARTS 256

typedef struct surfaces {
    const tcb_frames_job *f;
    tcb_uv_mesh *mesh; /* [f->n] */
} surfaces;

/* One texture and one face colouring serve all frames only if they agree. */
static int same_topology(const tcb_uv_mesh *a, const tcb_uv_mesh *b, int fa, int fb, tcb_error *merr)
{
    if (a->n_verts == b->n_verts && a->n_faces == b->n_faces && a->n_charts == b->n_charts &&
        !memcmp(a->faces, b->faces, 3 * (size_t)a->n_faces * sizeof *a->faces) &&
        (a->n_charts == 0 || (!memcmp(a->chart, b->chart, (size_t)a->n_verts * sizeof *a->chart) &&
                               !memcmp(a->uv, b->uv, 2 * (size_t)a->n_verts * sizeof *a->uv))))
        return TCB_OK;
    return tcb_fail(merr, TCB_ERR_INTERNAL,
                    "surface of frame %d differs from frame %d's in faces, charts or (u, v) (only vertices may move)",
                    fb, fa);
}

static int decode_frames(void *ctx, void *self, tcb_error *merr)
{
    surfaces *s = ctx;
    const tcb_frames_job *f = s->f;
    for (int k = 0; k < f->n; k++) {
        tcb_rng rng;
        tcb_frames_rng(f->cell, f->frames[k], -1, &rng);
        int rc = f->cell->ops->surface(self, f->cell->seq, f->frames[k], &rng, &s->mesh[k], merr);
        if (rc) {
            tcb_error_prefix(merr, "surface of frame %d: ", f->frames[k]);
            return rc;
        }
        if ((rc = tcb_surface_check(&s->mesh[k], f->frames[k], MAX_CHARTS, merr))) return rc;
        if (k && (rc = same_topology(&s->mesh[0], &s->mesh[k], f->frames[0], f->frames[k], merr))) return rc;
    }
    return TCB_OK;
}

static int write_obj(const tcb_frames_job *f, int k, const tcb_uv_mesh *m, const tcb_checker *c, tcb_error *err)
{
    char path[TCB_PATH_MAX];
    tcb_atomic_file af;
    int rc = tcb_path_join(path, sizeof path, err, "%s/frame_%d.obj", f->dir, f->frames[k]);
    if (!rc) rc = tcb_atomic_open(&af, path, err);
    if (rc) return rc;
    fprintf(af.fp, "# tcbench frames: %s, frame %d, normalized coordinates\nmtllib checker.mtl\n",
            f->cell->method->label, f->frames[k]);
    for (size_t v = 0; v < (size_t)m->n_verts; v++)
        fprintf(af.fp, "v %.7g %.7g %.7g\n", m->verts[3 * v], m->verts[3 * v + 1], m->verts[3 * v + 2]);
    for (size_t v = 0; v < (size_t)m->n_verts; v++) {
        float vt[2];
        tcb_checker_texcoord(c, m->chart[v], m->uv[2 * v], m->uv[2 * v + 1], vt);
        fprintf(af.fp, "vt %.6f %.6f\n", vt[0], vt[1]);
    }
    fprintf(af.fp, "usemtl checker\n");
    for (size_t t = 0; t < (size_t)m->n_faces; t++) {
        const int32_t *v = m->faces + 3 * t; /* OBJ counts from 1; vertex v has texture vertex v */
        fprintf(af.fp, "f %d/%d %d/%d %d/%d\n", v[0] + 1, v[0] + 1, v[1] + 1, v[1] + 1, v[2] + 1, v[2] + 1);
    }
    return tcb_atomic_commit(&af, err);
}

static int write_mtl(const char *dir, tcb_error *err)
{
    static const char mtl[] = "# tcbench frames: one checkerboard for every frame\n"
                              "newmtl checker\nKa 1 1 1\nKd 1 1 1\nKs 0 0 0\nillum 1\nmap_Kd checker.png\n";
    char path[TCB_PATH_MAX];
    int rc = tcb_path_join(path, sizeof path, err, "%s/checker.mtl", dir);
    return rc ? rc : tcb_write_file_atomic(path, mtl, sizeof mtl - 1, err);
}

/* Each face in the texture's colour at its UV centroid: the same for every
 * frame, as the topology is. */
static void face_colors(const tcb_uv_mesh *m, const tcb_checker *c, uint8_t *rgb)
{
    for (size_t t = 0; t < (size_t)m->n_faces; t++) {
        const int32_t *v = m->faces + 3 * t;
        double u = 0, w = 0;
        for (int a = 0; a < 3; a++) u += m->uv[2 * (size_t)v[a]] / 3.0, w += m->uv[2 * (size_t)v[a] + 1] / 3.0;
        tcb_checker_color(c, m->chart[v[0]], u, w, rgb + 3 * t);
    }
}

/* n_collapsed[k]: the collapsed patches of frame k's surface; said on
 * stderr (a warning, also under --quiet) in one line for all frames. */
static int collapsed_patches(const tcb_frames_job *f, const tcb_uv_mesh *mesh, int *n_collapsed, tcb_error *err)
{
    unsigned char flags[MAX_CHARTS];
    char msg[1024];
    int any = 0;
    size_t used = (size_t)snprintf(msg, sizeof msg, "%s seed %d: the surface collapsed:", f->cell->method->label,
                                   f->cell->seed);
    for (int k = 0; k < f->n; k++) {
        int rc = tcb_frames_collapsed(&mesh[k], f->cell->seq->areas[f->frames[k]], flags, &n_collapsed[k], err);
        if (rc) return rc;
        if (n_collapsed[k] && used < sizeof msg)
            used += (size_t)snprintf(msg + used, sizeof msg - used, "%s %d of %d patches in frame %d",
                                     any++ ? "," : "", n_collapsed[k], mesh[k].n_charts, f->frames[k]);
    }
    if (any)
        tcb_report_log(&f->cell->reporter, TCB_LOG_WARN,
                       "%s (a patch is collapsed when its area is under %g %% of its share of the frame's GT "
                       "surface: area / patches)",
                       msg, 100 * TCB_FRAMES_COLLAPSED);
    return TCB_OK;
}

/* The strip: with charts each face in its texture colour (face_rgb
 * [n_faces][3]), without each vertex in its colour (vertex_rgb
 * [n_verts][3]); the same colours in every frame. */
static int write_strip(const tcb_frames_job *f, const tcb_uv_mesh *mesh, const uint8_t *face_rgb,
                       const uint8_t *vertex_rgb, tcb_error *err)
{
    const tcb_uv_mesh *m0 = &mesh[0];
    tcb_render_panel panels[TCB_FRAMES_MAX];
    char titles[TCB_FRAMES_MAX][64], path[TCB_PATH_MAX];
    int n_collapsed[TCB_FRAMES_MAX];
    int rc = collapsed_patches(f, mesh, n_collapsed, err);
    if (rc) return rc;
    for (int k = 0; k < f->n; k++) {
        if (n_collapsed[k])
            snprintf(titles[k], sizeof titles[k], "frame %d: %d of %d patches collapsed", f->frames[k],
                     n_collapsed[k], mesh[k].n_charts);
        else
            snprintf(titles[k], sizeof titles[k], "frame %d", f->frames[k]);
        panels[k] = (tcb_render_panel){titles[k], mesh[k].verts, vertex_rgb, face_rgb};
    }
    const tcb_sequence *seq = f->cell->seq;
    rc = tcb_path_join(path, sizeof path, err, "%s/strip.png", f->dir);
    /* The view axis from the GT's first frame, as every strip and inspect's pair.png. */
    return rc ? rc : tcb_render_panels(path, panels, f->n, m0->n_verts, m0->faces, m0->n_faces,
                                       tcb_seq_frame(seq, 0), seq->n_verts, 0, err);
}

/* checker.png, checker.mtl, the textured OBJs and the strip. */
static int write_charted(const tcb_frames_job *f, const tcb_uv_mesh *mesh, tcb_error *err)
{
    tcb_checker c = tcb_checker_layout(mesh[0].n_charts);
    char path[TCB_PATH_MAX];
    uint8_t *rgb = malloc(3 * (size_t)mesh[0].n_faces);
    int rc = rgb ? tcb_mkdirs(f->dir, err) : tcb_fail(err, TCB_ERR_NOMEM, "out of memory for %d faces", mesh[0].n_faces);
    if (!rc) rc = tcb_path_join(path, sizeof path, err, "%s/checker.png", f->dir);
    if (!rc) rc = tcb_checker_write_png(&c, path, err);
    if (!rc) rc = write_mtl(f->dir, err);
    for (int k = 0; !rc && k < f->n; k++) rc = write_obj(f, k, &mesh[k], &c, err);
    if (!rc) face_colors(&mesh[0], &c, rgb);
    if (!rc) rc = write_strip(f, mesh, rgb, NULL, err);
    free(rgb);
    return rc;
}

/* A mesh without charts: each vertex coloured by its position in the first
 * frame drawn (the vertex is the same template point in every frame), as
 * frame_<f>.ply and the strip. */
static int write_chartless(const tcb_frames_job *f, const tcb_uv_mesh *mesh, tcb_error *err)
{
    const tcb_uv_mesh *m0 = &mesh[0];
    char path[TCB_PATH_MAX];
    uint8_t *rgb = malloc(3 * (size_t)m0->n_verts);
    int rc = rgb ? tcb_mkdirs(f->dir, err) : tcb_fail(err, TCB_ERR_NOMEM, "out of memory for %d vertices", m0->n_verts);
    if (!rc) tcb_color_by_position(m0->verts, m0->n_verts, rgb);
    for (int k = 0; !rc && k < f->n; k++) {
        rc = tcb_path_join(path, sizeof path, err, "%s/frame_%d.ply", f->dir, f->frames[k]);
        if (!rc) rc = tcb_ply_write(path, mesh[k].verts, m0->n_verts, m0->faces, m0->n_faces, rgb, err);
    }
    if (!rc) rc = write_strip(f, mesh, NULL, rgb, err);
    free(rgb);
    return rc;
}

int tcb_frames_texture(const tcb_frames_job *f, tcb_error *err)
{
    surfaces s = {f, calloc((size_t)f->n, sizeof *s.mesh)};
    if (!s.mesh) return tcb_fail(err, TCB_ERR_NOMEM, "out of memory");
    int rc = tcb_cell_use_method(f->cell, decode_frames, &s, err);
    if (!rc) rc = s.mesh[0].n_charts ? write_charted(f, s.mesh, err) : write_chartless(f, s.mesh, err);
    for (int k = 0; k < f->n; k++) tcb_uv_mesh_free(&s.mesh[k]);
    free(s.mesh);
    return rc;
}
