/* m_sL2 by frame distance |i − j| of one sequence, one line per method.
 *
 * The table pools all pairs; this shows how a method's error grows with the
 * time between the two frames. A temporally coherent method stays flat; one
 * that only tracks space (the `nearest` floor) climbs with the motion. */
#include <math.h>
#include <string.h>

#include "reports/chart.h"
#include "reports/writers.h"

/* Largest gap and largest mean error (table units) over the ok rows. */
static void extent(const tcb_rpt_block *b, int *max_gap, double *max_err)
{
    *max_gap = 1, *max_err = 0.0;
    for (int k = 0; k < b->n_rows; k++) {
        const tcb_rpt_row *r = &b->rows[k];
        for (int g = 0; g < r->n_gaps; g++) {
            if (!r->by_gap[g].n_pairs) continue;
            if (g > *max_gap) *max_gap = g;
            *max_err = fmax(*max_err, r->by_gap[g].sl2.mean * tcb_rpt_metrics[TCB_M_SL2].scale);
        }
    }
}

static void draw_row(tcb_chart *c, const tcb_rpt_row *r, int k)
{
    const double scale = tcb_rpt_metrics[TCB_M_SL2].scale;
    tcb_chart_series_begin(c, k);
    int started = 0;
    for (int g = 0; g < r->n_gaps; g++) {
        if (!r->by_gap[g].n_pairs) continue; /* distances without pairs: joined over */
        double x = tcb_chart_px(c, g), y = tcb_chart_py(c, r->by_gap[g].sl2.mean * scale);
        if (started++) cairo_line_to(c->cr, x, y);
        else cairo_move_to(c->cr, x, y);
    }
    cairo_stroke(c->cr);
    /* Dots show which distances have pairs behind them. */
    for (int g = 0; g < r->n_gaps; g++) {
        if (!r->by_gap[g].n_pairs) continue;
        cairo_arc(c->cr, tcb_chart_px(c, g), tcb_chart_py(c, r->by_gap[g].sl2.mean * scale), 3.0,
                  0.0, 2.0 * M_PI);
        cairo_fill(c->cr);
    }
    tcb_chart_series_end(c);
}

int tcb_rpt_plot_gap(const tcb_rpt_block *b, const char *path, tcb_error *err)
{
    int max_gap;
    double max_err;
    extent(b, &max_gap, &max_err);
    /* Integer ticks, at most ten of them. */
    int step = (int)tcb_chart_nice_ceil(ceil(max_gap / 10.0));
    int n_x = (max_gap + step - 1) / step;
    const tcb_chart_axis x = {(double)n_x * step, n_x, "%.0f", "frame distance |i − j|"};
    const tcb_chart_axis y = {max_err > 0.0 ? tcb_chart_nice_ceil(max_err) : 1.0, 5, "%g",
                              "mean m_sL2 (×1e3)"};
    tcb_chart c;
    tcb_chart_begin(&c, &x, &y);
    for (int k = 0; k < b->n_rows; k++)
        if (b->rows[k].n_gaps) draw_row(&c, &b->rows[k], k);
    tcb_chart_legend(&c, b, "method (m_sL2)", TCB_M_SL2);
    tcb_chart_title(&c, b, "m_sL2 by frame distance");
    return tcb_chart_finish(&c, path, err);
}
