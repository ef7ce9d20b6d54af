/* PCK curves of one sequence, one line per method (cairo, 900×600 PNG).
 *
 * x: threshold on the SQUARED distance, 0 … TCB_PCK_MAX (reference-protocol
 * §5.5); y: PCK in percent, always the full 0 … 100 so that plots of
 * different sequences compare at a glance. The legend sits in its own panel
 * right of the axes, so it can never hide a curve. */
#include <cairo.h>
#include <math.h>
#include <string.h>
#include <unistd.h>

#include "reports/writers.h"
#include "tcb/fsutil.h"

enum { W = 900, H = 600 };
/* Plot area in device pixels. */
static const double X0 = 84, X1 = 650, Y0 = 78, Y1 = 516;
static const double LEGEND_X = 676, LEGEND_W = 210;
static const char *const FONT = "DejaVu Sans";

/* d3 category10: distinct hues that stay readable on white. */
static const double PALETTE[][3] = {
    {0.122, 0.467, 0.706}, {1.000, 0.498, 0.055}, {0.173, 0.627, 0.173}, {0.839, 0.153, 0.157},
    {0.580, 0.404, 0.741}, {0.549, 0.337, 0.294}, {0.890, 0.467, 0.761}, {0.498, 0.498, 0.498},
    {0.737, 0.741, 0.133}, {0.090, 0.745, 0.812},
};
#define N_COLOURS ((int)(sizeof PALETTE / sizeof PALETTE[0]))

static double px(double t) { return X0 + (X1 - X0) * t / TCB_PCK_MAX; }
static double py(double pct) { return Y1 - (Y1 - Y0) * pct / 100.0; }

static void font(cairo_t *cr, double size, int bold)
{
    cairo_select_font_face(cr, FONT, CAIRO_FONT_SLANT_NORMAL,
                           bold ? CAIRO_FONT_WEIGHT_BOLD : CAIRO_FONT_WEIGHT_NORMAL);
    cairo_set_font_size(cr, size);
}

/* Text anchored at (x, y) on its baseline; align 0 left, 0.5 centre, 1 right. */
static void text(cairo_t *cr, double x, double y, double align, const char *s)
{
    cairo_text_extents_t e;
    cairo_text_extents(cr, s, &e);
    cairo_move_to(cr, x - align * e.x_advance, y);
    cairo_show_text(cr, s);
}

static void draw_frame(cairo_t *cr)
{
    char label[32];
    cairo_set_line_width(cr, 1);
    font(cr, 13, 0);
    for (int k = 0; k <= 5; k++) { /* x ticks every 0.004, y ticks every 20 % */
        double t = TCB_PCK_MAX * k / 5, pct = 20.0 * k;
        cairo_set_source_rgb(cr, 0.90, 0.90, 0.90);
        cairo_move_to(cr, round(px(t)) + 0.5, Y0);
        cairo_line_to(cr, round(px(t)) + 0.5, Y1);
        cairo_move_to(cr, X0, round(py(pct)) + 0.5);
        cairo_line_to(cr, X1, round(py(pct)) + 0.5);
        cairo_stroke(cr);
        cairo_set_source_rgb(cr, 0.15, 0.15, 0.15);
        cairo_move_to(cr, round(px(t)) + 0.5, Y1);
        cairo_line_to(cr, round(px(t)) + 0.5, Y1 + 6);
        cairo_move_to(cr, X0 - 6, round(py(pct)) + 0.5);
        cairo_line_to(cr, X0, round(py(pct)) + 0.5);
        cairo_stroke(cr);
        snprintf(label, sizeof label, k ? "%.3f" : "0", t);
        text(cr, px(t), Y1 + 24, 0.5, label);
        snprintf(label, sizeof label, "%.0f", pct);
        text(cr, X0 - 10, py(pct) + 5, 1, label);
    }
    cairo_set_source_rgb(cr, 0.15, 0.15, 0.15);
    cairo_rectangle(cr, X0 + 0.5, Y0 + 0.5, X1 - X0 - 1, Y1 - Y0 - 1);
    cairo_stroke(cr);
    font(cr, 14, 0);
    text(cr, (X0 + X1) / 2, Y1 + 54, 0.5, "threshold on squared distance");
    cairo_save(cr);
    cairo_translate(cr, X0 - 52, (Y0 + Y1) / 2);
    cairo_rotate(cr, -M_PI / 2);
    text(cr, 0, 0, 0.5, "PCK (%)");
    cairo_restore(cr);
}

static void set_style(cairo_t *cr, int k)
{
    const double *c = PALETTE[k % N_COLOURS];
    cairo_set_source_rgb(cr, c[0], c[1], c[2]);
    cairo_set_line_width(cr, 2.2);
    /* Past ten methods the colours repeat; dashes keep the lines apart. */
    static const double dash[] = {7, 4};
    cairo_set_dash(cr, dash, k >= N_COLOURS ? 2 : 0, 0);
}

static void draw_curves(cairo_t *cr, const tcb_rpt_block *b)
{
    cairo_save(cr);
    /* A curve at exactly 100 % must stay visible, not be half clipped. */
    cairo_rectangle(cr, X0, Y0 - 2, X1 - X0, Y1 - Y0 + 2);
    cairo_clip(cr);
    cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
    for (int k = 0; k < b->n_rows; k++) {
        const tcb_rpt_row *r = &b->rows[k];
        if (strcmp(r->status, "ok")) continue;
        set_style(cr, k);
        for (int s = 0; s < TCB_PCK_STEPS; s++) {
            double x = px(tcb_pck_threshold(s)), y = py(r->pck[s]);
            if (s == 0) cairo_move_to(cr, x, y);
            else cairo_line_to(cr, x, y);
        }
        cairo_stroke(cr);
    }
    cairo_restore(cr);
}

/* The label fitted to `width`, ellipsized at a UTF-8 boundary when too long. */
static void fit_label(cairo_t *cr, char *s, size_t size, double width)
{
    cairo_text_extents_t e;
    size_t n = strlen(s);
    cairo_text_extents(cr, s, &e);
    while (e.x_advance > width && n > 1) {
        do n--; while (n > 0 && ((unsigned char)s[n] & 0xC0) == 0x80);
        if (n + sizeof "…" > size) continue;
        memcpy(s + n, "…", sizeof "…");
        cairo_text_extents(cr, s, &e);
    }
}

static void draw_legend(cairo_t *cr, const tcb_rpt_block *b)
{
    double y = Y0 + 8;
    font(cr, 13, 1);
    cairo_set_source_rgb(cr, 0.15, 0.15, 0.15);
    text(cr, LEGEND_X, y + 4, 0, "method (AUC %)");
    y += 28;
    /* Many methods close ranks rather than run off the image. */
    double step = fmin(24.0, (H - 16 - y) / (b->n_rows > 0 ? b->n_rows : 1));
    for (int k = 0; k < b->n_rows; k++, y += step) {
        const tcb_rpt_row *r = &b->rows[k];
        char label[160];
        int ok = !strcmp(r->status, "ok");
        if (ok) {
            set_style(cr, k);
            cairo_move_to(cr, LEGEND_X, y);
            cairo_line_to(cr, LEGEND_X + 28, y);
            cairo_stroke(cr);
            snprintf(label, sizeof label, "%s (%.2f)", r->method, r->mean[TCB_M_AUC]);
            cairo_set_source_rgb(cr, 0.15, 0.15, 0.15);
        } else {
            snprintf(label, sizeof label, "%s: %s", r->method, r->status_text);
            cairo_set_source_rgb(cr, 0.55, 0.55, 0.55);
        }
        font(cr, 13, 0);
        fit_label(cr, label, sizeof label, LEGEND_W - 36);
        text(cr, LEGEND_X + 36, y + 5, 0, label);
    }
}

static void draw_title(cairo_t *cr, const tcb_rpt_block *b)
{
    char s[512];
    cairo_set_source_rgb(cr, 0.1, 0.1, 0.1);
    font(cr, 19, 1);
    snprintf(s, sizeof s, "PCK — %s / %s", b->dataset, b->sequence);
    text(cr, X0, 36, 0, s);
    font(cr, 13, 0);
    cairo_set_source_rgb(cr, 0.38, 0.38, 0.38);
    if (b->n_pairs_min == b->n_pairs_max)
        snprintf(s, sizeof s, "%s sequence · %d pairs · seeds %s", b->role, b->n_pairs_min,
                 b->seeds);
    else
        snprintf(s, sizeof s, "%s sequence · %d–%d pairs · seeds %s", b->role, b->n_pairs_min,
                 b->n_pairs_max, b->seeds);
    text(cr, X0, 58, 0, s);
}

int tcb_rpt_pck_name(const tcb_rpt_block *b, char *out, size_t size, tcb_error *err)
{
    int rc = tcb_path_join(out, size, err, "pck_%s_%s.png", b->dataset, b->sequence);
    for (char *p = out; !rc && *p; p++) {
        int ok = (*p >= 'a' && *p <= 'z') || (*p >= 'A' && *p <= 'Z') || (*p >= '0' && *p <= '9') ||
                 *p == '_' || *p == '-' || *p == '.';
        if (!ok) *p = '_';
    }
    return rc;
}

int tcb_rpt_plot_pck(const tcb_rpt_block *b, const char *path, tcb_error *err)
{
    char tmp[TCB_PATH_MAX];
    int rc = tcb_temp_path_for(path, tmp, sizeof tmp, err);
    if (rc) return rc;
    cairo_surface_t *surface = cairo_image_surface_create(CAIRO_FORMAT_RGB24, W, H);
    cairo_t *cr = cairo_create(surface);
    cairo_set_source_rgb(cr, 1, 1, 1);
    cairo_paint(cr);
    draw_frame(cr);
    draw_curves(cr, b);
    draw_legend(cr, b);
    draw_title(cr, b);
    cairo_status_t st = cairo_status(cr);
    cairo_destroy(cr);
    if (st == CAIRO_STATUS_SUCCESS) st = cairo_surface_write_to_png(surface, tmp);
    cairo_surface_destroy(surface);
    if (st != CAIRO_STATUS_SUCCESS) {
        unlink(tmp);
        return tcb_fail(err, TCB_ERR_IO, "%s: cannot draw the PCK plot: %s", path,
                        cairo_status_to_string(st));
    }
    return tcb_publish(tmp, path, err);
}
