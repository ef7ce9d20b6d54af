/* m_sL2 by frame distance |i − j| of one sequence, one line per method.
 *
 * The table pools all pairs; this shows how a method's error grows with the
 * time between the two frames. A temporally coherent method stays flat; one
 * that only tracks space (the `nearest` floor) climbs with the motion.
 *
 * The errors of one report span decades (an untrained atlas two orders
 * above nrICP, the oracle at 0), so the y axis is logarithmic: on a linear
 * one scaled to the worst method the best lay flat at the bottom. Values
 * under the axis's floor (0 included) sit on the floor as ▼. A line joins
 * two distances only when every distance between them has pairs. */
#include <math.h>
#include <string.h>

#include "reports/chart.h"
#include "reports/writers.h"

/* At most this many decades: a floor lower than top / 10^4 would spend the
 * plot on values no one compares. */
#define MAX_DECADES 4

/* Largest gap, and the largest and smallest positive mean error (table
 * units) over the rows; *min_pos 0 when none is positive. */
static void extent(const tcb_rpt_block *b, int *max_gap, double *max_err, double *min_pos)
{
    *max_gap = 1, *max_err = 0.0, *min_pos = 0.0;
    for (int k = 0; k < b->n_rows; k++) {
        const tcb_rpt_row *r = &b->rows[k];
        for (int g = 0; g < r->n_gaps; g++) {
            if (!r->by_gap[g].n_pairs) continue;
            double e = r->by_gap[g].sl2.mean * tcb_rpt_metrics[TCB_M_SL2].scale;
            if (g > *max_gap) *max_gap = g;
            *max_err = fmax(*max_err, e);
            if (e > 0 && (*min_pos == 0 || e < *min_pos)) *min_pos = e;
        }
    }
}

/* The log axis: from the power of ten at or under the smallest positive
 * value to the one at or over the largest, at most MAX_DECADES. */
static tcb_chart_axis y_axis(double max_err, double min_pos)
{
    double top = max_err > 0 ? pow(10.0, ceil(log10(max_err) - 1e-9)) : 1.0;
    double floor_ = min_pos > 0 ? pow(10.0, floor(log10(min_pos) + 1e-9)) : top / 10;
    floor_ = fmin(fmax(floor_, top / pow(10.0, MAX_DECADES)), top / 10);
    return (tcb_chart_axis){.min = floor_, .max = top, .format = "%g", .label = "mean m_sL2 (×1e3, log scale)",
                            .log = 1};
}

/* A point's y on the plot: values under the floor on the floor. */
static double py(const tcb_chart *c, double v) { return tcb_chart_py(c, fmax(v, c->y.min)); }

static void marker(tcb_chart *c, double x, double v)
{
    double y = py(c, v);
    if (v >= c->y.min) {
        cairo_arc(c->cr, x, y, 3.0, 0.0, 2.0 * M_PI);
    } else { /* ▼: the true value is lower than drawn */
        cairo_move_to(c->cr, x - 5, y - 9);
        cairo_line_to(c->cr, x + 5, y - 9);
        cairo_line_to(c->cr, x, y);
        cairo_close_path(c->cr);
    }
    cairo_fill(c->cr);
}

static void draw_row(tcb_chart *c, const tcb_rpt_block *b, int k)
{
    const tcb_rpt_row *r = &b->rows[k];
    const double scale = tcb_rpt_metrics[TCB_M_SL2].scale;
    tcb_chart_series_begin(c, k);
    for (int g = 0; g < r->n_gaps; g++) {
        if (!r->by_gap[g].n_pairs) continue;
        double x = tcb_chart_px(c, g), y = py(c, r->by_gap[g].sl2.mean * scale);
        /* a distance without pairs breaks the line: nothing was measured there */
        if (g > 0 && r->by_gap[g - 1].n_pairs) cairo_line_to(c->cr, x, y);
        else cairo_move_to(c->cr, x, y);
    }
    cairo_stroke(c->cr);
    /* Dots show which distances have pairs behind them. */
    for (int g = 0; g < r->n_gaps; g++)
        if (r->by_gap[g].n_pairs) marker(c, tcb_chart_px(c, g), r->by_gap[g].sl2.mean * scale);
    tcb_chart_series_end(c);
}

int tcb_rpt_plot_gap(const tcb_rpt_block *b, const char *path, tcb_error *err)
{
    int max_gap;
    double max_err, min_pos;
    extent(b, &max_gap, &max_err, &min_pos);
    /* Integer ticks, at most ten of them. */
    int step = (int)tcb_chart_nice_ceil(ceil(max_gap / 10.0));
    int n_x = (max_gap + step - 1) / step;
    const tcb_chart_axis x = {.max = (double)n_x * step, .n_ticks = n_x, .format = "%.0f",
                              .label = "frame distance |i − j|"};
    const tcb_chart_axis y = y_axis(max_err, min_pos);
    tcb_chart c;
    tcb_chart_begin(&c, &x, &y, b);
    for (int k = 0; k < b->n_rows; k++)
        if (b->rows[k].n_gaps) draw_row(&c, b, k);
    tcb_chart_legend(&c, b, "method (m_sL2)", TCB_M_SL2);
    tcb_chart_title(&c, b, "m_sL2 by frame distance");
    char note[160];
    snprintf(note, sizeof note, "▼ on the bottom edge: under %g (0 included); no line across distances without pairs",
             y.min);
    tcb_chart_note(&c, note);
    return tcb_chart_finish(&c, path, err);
}
