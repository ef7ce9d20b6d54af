/* The checkerboard texture; see checker.h. */
#include "views/checker.h"

#include <math.h>
#include <stddef.h>

#include "views/render.h"

enum { INNER = TCB_CHECKER_CELL - 2 * TCB_CHECKER_GUTTER };

tcb_checker tcb_checker_layout(int n_charts)
{
    int cols = 1;
    while (cols * cols < n_charts) cols++;
    return (tcb_checker){n_charts, cols, (n_charts + cols - 1) / cols};
}

static double clamp01(double x) { return x < 0 ? 0 : x > 1 ? 1 : x; }

/* HSV with full value range to RGB bytes. */
static void hsv(double h, double s, double v, uint8_t rgb[3])
{
    double f = 6 * (h - floor(h)), p = v * (1 - s);
    int sector = (int)f % 6;
    f -= floor(f);
    double q = v * (1 - s * f), t = v * (1 - s * (1 - f));
    const double table[6][3] = {{v, t, p}, {q, v, p}, {p, v, t}, {p, q, v}, {t, p, v}, {v, p, q}};
    for (int a = 0; a < 3; a++) rgb[a] = (uint8_t)lround(255 * table[sector][a]);
}

void tcb_checker_color(const tcb_checker *c, int chart, double u, double v, uint8_t rgb[3])
{
    (void)c; /* the colours depend on the chart alone; the layout is for where they go */
    int iu = (int)(clamp01(u) * TCB_CHECKER_CHECKS), iv = (int)(clamp01(v) * TCB_CHECKER_CHECKS);
    iu = iu < TCB_CHECKER_CHECKS ? iu : TCB_CHECKER_CHECKS - 1;
    iv = iv < TCB_CHECKER_CHECKS ? iv : TCB_CHECKER_CHECKS - 1;
    if (iu == 0 && iv == 0) {
        rgb[0] = rgb[1] = rgb[2] = 250;
        return;
    }
    double hue = chart * 0.6180339887498949;
    if ((iu + iv) % 2) hsv(hue, 0.85, 0.62, rgb);
    else hsv(hue, 0.40, 0.97, rgb);
}

void tcb_checker_texcoord(const tcb_checker *c, int chart, double u, double v, float vt[2])
{
    double x = (chart % c->cols) * TCB_CHECKER_CELL + TCB_CHECKER_GUTTER + clamp01(u) * INNER;
    double y = (chart / c->cols) * TCB_CHECKER_CELL + TCB_CHECKER_GUTTER + (1 - clamp01(v)) * INNER;
    vt[0] = (float)(x / (c->cols * TCB_CHECKER_CELL));
    vt[1] = (float)(1 - y / (c->rows * TCB_CHECKER_CELL));
}

/* Pixel (x, y) of the image: a chart's colour, the gutter its square's
 * nearest edge, a cell without a chart light grey. */
static void pixel(const tcb_checker *c, int x, int y, uint8_t rgb[3])
{
    int chart = (y / TCB_CHECKER_CELL) * c->cols + x / TCB_CHECKER_CELL;
    if (chart >= c->n_charts) {
        rgb[0] = rgb[1] = rgb[2] = 200;
        return;
    }
    double u = (x % TCB_CHECKER_CELL - TCB_CHECKER_GUTTER + 0.5) / INNER;
    double v = 1 - (y % TCB_CHECKER_CELL - TCB_CHECKER_GUTTER + 0.5) / INNER;
    tcb_checker_color(c, chart, u, v, rgb);
}

int tcb_checker_write_png(const tcb_checker *c, const char *path, tcb_error *err)
{
    int w = c->cols * TCB_CHECKER_CELL, h = c->rows * TCB_CHECKER_CELL;
    cairo_surface_t *s = cairo_image_surface_create(CAIRO_FORMAT_RGB24, w, h);
    if (cairo_surface_status(s) == CAIRO_STATUS_SUCCESS) {
        cairo_surface_flush(s);
        unsigned char *data = cairo_image_surface_get_data(s);
        int stride = cairo_image_surface_get_stride(s);
        for (int y = 0; y < h; y++)
            for (int x = 0; x < w; x++) {
                uint8_t rgb[3];
                pixel(c, x, y, rgb);
                uint32_t *px = (uint32_t *)(void *)(data + (size_t)y * stride) + x;
                *px = (uint32_t)rgb[0] << 16 | (uint32_t)rgb[1] << 8 | rgb[2]; /* RGB24: native 0x00RRGGBB */
            }
        cairo_surface_mark_dirty(s);
    }
    return tcb_render_save_png(s, path, err);
}
