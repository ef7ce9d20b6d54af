/* The shared plot frame of the reports (cairo); see chart.h. */
#include "reports/chart.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

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
/* Solid, dashed, dotted, dash-dot: a second cue where two labels share a colour. */
static const double DASHES[][4] = {{0}, {7, 4}, {2, 3}, {8, 3, 2, 3}};
static const int N_DASH_STEPS[] = {0, 2, 2, 4};
#define N_DASHES ((int)(sizeof DASHES / sizeof DASHES[0]))
/* A salt under which the labels of the configs shipped before pdg got
 * distinct colours: kept so that their pictures keep theirs. Beyond a
 * handful of labels no salt can promise that (nine labels in ten colours
 * collide for all but 0.4% of hashes), so tcb_chart_styles resolves a
 * plot's collisions instead. */
#define STYLE_SALT 1869495u

int tcb_chart_style_of(const char *label)
{
    if (!label) return 0;
    uint32_t h = 2166136261u ^ STYLE_SALT; /* FNV-1a, then murmur3's finalizer: every bit mixes */
    for (const unsigned char *p = (const unsigned char *)label; *p; p++) h = (h ^ *p) * 16777619u;
    h ^= h >> 16, h *= 0x85ebca6bu, h ^= h >> 13, h *= 0xc2b2ae35u, h ^= h >> 16;
    return (int)(h % (N_COLOURS * N_DASHES));
}

/* The key two labels of one plot must not share: the colour while there are
 * colours for all, else the colour and dash. */
static int style_key(int style, int n) { return n <= N_COLOURS ? style % N_COLOURS : style; }

void tcb_chart_styles(const char *const *label, int n, int *style)
{
    enum { N_STYLES = N_COLOURS * N_DASHES };
    int n_keys = n <= N_COLOURS ? N_COLOURS : N_STYLES, taken[N_STYLES] = {0}, n_taken = 0;
    for (int k = 0; k < n; k++) style[k] = -1;
    for (int done = 0; done < n; done++) {
        int k = -1; /* the first label, in strcmp order, not yet styled */
        for (int j = 0; j < n; j++)
            if (style[j] < 0 && (k < 0 || strcmp(label[j], label[k]) < 0)) k = j;
        int own = tcb_chart_style_of(label[k]), key = style_key(own, n);
        /* more labels than styles: the later ones share (their own style) */
        if (n_taken < n_keys)
            while (taken[key]) key = (key + 1) % n_keys;
        if (!taken[key]) taken[key] = 1, n_taken++;
        style[k] = n <= N_COLOURS ? own / N_COLOURS * N_COLOURS + key : key;
    }
}

/* Where v lies along the axis, 0 at its start and 1 at its end. */
static double axis_frac(const tcb_chart_axis *a, double v)
{
    if (a->log) return (log10(v) - log10(a->min)) / (log10(a->max) - log10(a->min));
    return (v - a->min) / (a->max - a->min);
}

double tcb_chart_px(const tcb_chart *c, double x) { return X0 + (X1 - X0) * axis_frac(&c->x, x); }
double tcb_chart_py(const tcb_chart *c, double y) { return Y1 - (Y1 - Y0) * axis_frac(&c->y, y); }

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

enum { MAX_TICKS = 64 };

/* The axis's ticks: linear, n_ticks + 1 labelled ones from min to max; log,
 * a labelled one at each power of ten and grid lines at 2× and 5×. */
static int axis_ticks(const tcb_chart_axis *a, double *v, int *labelled)
{
    int n = 0;
    if (!a->log) {
        for (int k = 0; k <= a->n_ticks && n < MAX_TICKS; k++, n++)
            v[n] = a->min + (a->max - a->min) * k / a->n_ticks, labelled[n] = 1;
        return n;
    }
    static const double minor[] = {1, 2, 5};
    for (double d = pow(10.0, floor(log10(a->min) + 1e-9)); d <= a->max * (1 + 1e-9) && n < MAX_TICKS; d *= 10)
        for (int m = 0; m < 3 && n < MAX_TICKS; m++)
            if (d * minor[m] >= a->min * (1 - 1e-9) && d * minor[m] <= a->max * (1 + 1e-9))
                v[n] = d * minor[m], labelled[n++] = m == 0;
    return n;
}

static void tick_label(const tcb_chart_axis *a, double v, char *out, size_t size)
{
    if (fabs(v) < 1e-12 * fmax(fabs(a->min), fabs(a->max))) snprintf(out, size, "0");
    else snprintf(out, size, a->format, v);
}

/* The grid line, tick mark and label of each tick of the x axis (y: 0)
 * or the y axis (1). */
static void draw_ticks(tcb_chart *c, int y_axis)
{
    cairo_t *cr = c->cr;
    const tcb_chart_axis *a = y_axis ? &c->y : &c->x;
    double v[MAX_TICKS];
    int labelled[MAX_TICKS], n = axis_ticks(a, v, labelled);
    for (int k = 0; k < n; k++) {
        double at = round(y_axis ? tcb_chart_py(c, v[k]) : tcb_chart_px(c, v[k])) + 0.5, g = labelled[k] ? 0.90 : 0.95;
        cairo_set_source_rgb(cr, g, g, g);
        cairo_move_to(cr, y_axis ? X0 : at, y_axis ? at : Y0);
        cairo_line_to(cr, y_axis ? X1 : at, y_axis ? at : Y1);
        cairo_stroke(cr);
        if (!labelled[k]) continue;
        char label[32];
        cairo_set_source_rgb(cr, 0.15, 0.15, 0.15);
        cairo_move_to(cr, y_axis ? X0 - 6 : at, y_axis ? at : Y1);
        cairo_line_to(cr, y_axis ? X0 : at, y_axis ? at : Y1 + 6);
        cairo_stroke(cr);
        tick_label(a, v[k], label, sizeof label);
        if (y_axis) text(cr, X0 - 10, at + 5, 1, label);
        else text(cr, at, Y1 + 24, 0.5, label);
    }
}

/* The styles of block b's rows (rows are distinct methods); NULL when the
 * array cannot be had, which tcb_chart_finish reports. */
static int *row_styles(const tcb_rpt_block *b)
{
    int *style = malloc(sizeof *style * (size_t)b->n_rows);
    const char **label = malloc(sizeof *label * (size_t)b->n_rows);
    if (style && label) {
        for (int k = 0; k < b->n_rows; k++) label[k] = b->rows[k].method;
        tcb_chart_styles(label, b->n_rows, style);
    } else {
        free(style), style = NULL;
    }
    free(label);
    return style;
}

void tcb_chart_begin(tcb_chart *c, const tcb_chart_axis *x, const tcb_chart_axis *y, const tcb_rpt_block *b)
{
    c->x = *x, c->y = *y;
    c->n_rows = b ? b->n_rows : 0;
    c->style = c->n_rows ? row_styles(b) : NULL;
    c->surface = cairo_image_surface_create(CAIRO_FORMAT_RGB24, W, H);
    c->cr = cairo_create(c->surface);
    cairo_t *cr = c->cr;
    cairo_set_source_rgb(cr, 1, 1, 1);
    cairo_paint(cr);
    cairo_set_line_width(cr, 1);
    font(cr, 13, 0);
    draw_ticks(c, 0);
    draw_ticks(c, 1);
    cairo_set_source_rgb(cr, 0.15, 0.15, 0.15);
    cairo_rectangle(cr, X0 + 0.5, Y0 + 0.5, X1 - X0 - 1, Y1 - Y0 - 1);
    cairo_stroke(cr);
    font(cr, 14, 0);
    text(cr, (X0 + X1) / 2, Y1 + 54, 0.5, x->label);
    cairo_save(cr);
    cairo_translate(cr, X0 - 52, (Y0 + Y1) / 2);
    cairo_rotate(cr, -M_PI / 2);
    text(cr, 0, 0, 0.5, y->label);
    cairo_restore(cr);
}

static void set_style(cairo_t *cr, int s)
{
    const double *rgb = PALETTE[s % N_COLOURS];
    cairo_set_source_rgb(cr, rgb[0], rgb[1], rgb[2]);
    cairo_set_line_width(cr, 2.2);
    cairo_set_dash(cr, DASHES[s / N_COLOURS], N_DASH_STEPS[s / N_COLOURS], 0);
}

/* Row k's style; the first (solid, first colour) for a plot of one series. */
static int row_style(const tcb_chart *c, int k) { return k >= 0 && k < c->n_rows && c->style ? c->style[k] : 0; }

void tcb_chart_series_begin(tcb_chart *c, int k)
{
    cairo_save(c->cr);
    /* A line at exactly the axis end must stay visible, not be half clipped. */
    cairo_rectangle(c->cr, X0, Y0 - 2, X1 - X0, Y1 - Y0 + 2);
    cairo_clip(c->cr);
    cairo_set_line_join(c->cr, CAIRO_LINE_JOIN_ROUND);
    set_style(c->cr, row_style(c, k));
}

void tcb_chart_series_end(tcb_chart *c) { cairo_restore(c->cr); }

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

void tcb_chart_legend(tcb_chart *c, const tcb_rpt_block *b, const char *heading, int metric)
{
    cairo_t *cr = c->cr;
    double y = Y0 + 8;
    font(cr, 13, 1);
    cairo_set_source_rgb(cr, 0.15, 0.15, 0.15);
    text(cr, LEGEND_X, y + 4, 0, heading);
    y += 28;
    /* Many methods close ranks rather than run off the image. */
    double step = fmin(24.0, (H - 16 - y) / (b->n_rows > 0 ? b->n_rows : 1));
    for (int k = 0; k < b->n_rows; k++, y += step) {
        const tcb_rpt_row *r = &b->rows[k];
        char label[160];
        if (!strcmp(r->status, "ok")) {
            set_style(cr, row_style(c, k));
            cairo_move_to(cr, LEGEND_X, y);
            cairo_line_to(cr, LEGEND_X + 28, y);
            cairo_stroke(cr);
            if (r->has[metric])
                snprintf(label, sizeof label, "%s (%.*f)", r->method,
                         tcb_rpt_metrics[metric].decimals, r->mean[metric]);
            else /* e.g. no geodesic error in an older cell */
                snprintf(label, sizeof label, "%s (-)", r->method);
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

void tcb_chart_headline(tcb_chart *c, const char *title, const char *subtitle)
{
    cairo_t *cr = c->cr;
    cairo_set_source_rgb(cr, 0.1, 0.1, 0.1);
    font(cr, 19, 1);
    text(cr, X0, 36, 0, title);
    font(cr, 13, 0);
    cairo_set_source_rgb(cr, 0.38, 0.38, 0.38);
    text(cr, X0, 58, 0, subtitle);
}

void tcb_chart_note(tcb_chart *c, const char *note)
{
    font(c->cr, 12, 0);
    cairo_set_source_rgb(c->cr, 0.38, 0.38, 0.38);
    text(c->cr, X0 - 60, H - 10, 0, note);
}

void tcb_chart_title(tcb_chart *c, const tcb_rpt_block *b, const char *what)
{
    char title[512], sub[512];
    snprintf(title, sizeof title, "%s — %s / %s", what, b->dataset, b->sequence);
    if (b->n_pairs_min == b->n_pairs_max)
        snprintf(sub, sizeof sub, "%s sequence · %d pairs · seeds %s", b->role, b->n_pairs_min, b->seeds);
    else
        snprintf(sub, sizeof sub, "%s sequence · %d–%d pairs · seeds %s", b->role, b->n_pairs_min,
                 b->n_pairs_max, b->seeds);
    tcb_chart_headline(c, title, sub);
}

int tcb_chart_finish(tcb_chart *c, const char *path, tcb_error *err)
{
    char tmp[TCB_PATH_MAX];
    cairo_status_t st = cairo_status(c->cr);
    if (c->n_rows && !c->style) st = CAIRO_STATUS_NO_MEMORY;
    free(c->style), c->style = NULL;
    cairo_destroy(c->cr);
    int rc = tcb_temp_path_for(path, tmp, sizeof tmp, err);
    if (!rc && st == CAIRO_STATUS_SUCCESS) st = cairo_surface_write_to_png(c->surface, tmp);
    cairo_surface_destroy(c->surface);
    c->cr = NULL, c->surface = NULL;
    if (rc) return rc;
    if (st != CAIRO_STATUS_SUCCESS) {
        unlink(tmp);
        return tcb_fail(err, TCB_ERR_IO, "%s: cannot draw the plot: %s", path,
                        cairo_status_to_string(st));
    }
    return tcb_publish(tmp, path, err);
}

int tcb_chart_file_name(const tcb_rpt_block *b, const char *prefix, char *out, size_t size,
                        tcb_error *err)
{
    int rc = tcb_path_join(out, size, err, "%s_%s_%s.png", prefix, b->dataset, b->sequence);
    for (char *p = out; !rc && *p; p++) {
        int ok = (*p >= 'a' && *p <= 'z') || (*p >= 'A' && *p <= 'Z') || (*p >= '0' && *p <= '9') ||
                 *p == '_' || *p == '-' || *p == '.';
        if (!ok) *p = '_';
    }
    return rc;
}

double tcb_chart_nice_ceil(double v)
{
    double p = pow(10.0, floor(log10(v)));
    static const double steps[] = {1.0, 2.0, 2.5, 5.0, 10.0};
    for (size_t k = 0; k < sizeof steps / sizeof steps[0]; k++)
        if (steps[k] * p >= v * (1.0 - 1e-12)) return steps[k] * p;
    return 10.0 * p;
}
