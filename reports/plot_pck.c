/* PCK curves of one sequence, one line per method: the paper's and the
 * geodesic one, each in its own file.
 *
 * Paper's: x is the threshold on the SQUARED distance, 0 … TCB_PCK_MAX
 * (reference-protocol §5.5). Geodesic: x is the threshold on the geodesic
 * error over sqrt(area), 0 … TCB_GEO_PCK_MAX (tcb/geodesic.h). y: PCK in
 * percent, always the full 0 … 100 so that plots of different sequences
 * compare at a glance. */
#include <string.h>

#include "reports/chart.h"
#include "reports/writers.h"

/* What distinguishes the two plots. */
typedef struct pck_plot {
    tcb_chart_axis x;
    double (*threshold)(int s);
    int steps;
    int metric;                                    /* whose rows have the curve, legend value */
    const double *(*curve)(const tcb_rpt_row *r);  /* percent [steps] */
    const char *legend, *title;
} pck_plot;

static const double *paper_curve(const tcb_rpt_row *r) { return r->pck; }
static const double *geo_curve(const tcb_rpt_row *r) { return r->geo_pck; }

static int plot(const tcb_rpt_block *b, const pck_plot *p, const char *path, tcb_error *err)
{
    const tcb_chart_axis y = {.max = 100.0, .n_ticks = 5, .format = "%.0f", .label = "PCK (%)"};
    tcb_chart c;
    tcb_chart_begin(&c, &p->x, &y, b);
    for (int k = 0; k < b->n_rows; k++) {
        const tcb_rpt_row *r = &b->rows[k];
        if (strcmp(r->status, "ok") || !r->has[p->metric]) continue;
        const double *pck = p->curve(r);
        tcb_chart_series_begin(&c, k);
        for (int s = 0; s < p->steps; s++) {
            double px = tcb_chart_px(&c, p->threshold(s)), py = tcb_chart_py(&c, pck[s]);
            if (s == 0) cairo_move_to(c.cr, px, py);
            else cairo_line_to(c.cr, px, py);
        }
        cairo_stroke(c.cr);
        tcb_chart_series_end(&c);
    }
    tcb_chart_legend(&c, b, p->legend, p->metric);
    tcb_chart_title(&c, b, p->title);
    return tcb_chart_finish(&c, path, err);
}

int tcb_rpt_plot_pck(const tcb_rpt_block *b, const char *path, tcb_error *err)
{
    const pck_plot p = {{.max = TCB_PCK_MAX, .n_ticks = 5, .format = "%.3f", .label = "threshold on squared distance"},
                        tcb_pck_threshold, TCB_PCK_STEPS, TCB_M_AUC, paper_curve,
                        "method (AUC %)", "PCK"};
    return plot(b, &p, path, err);
}

int tcb_rpt_plot_pck_geo(const tcb_rpt_block *b, const char *path, tcb_error *err)
{
    const pck_plot p = {{.max = TCB_GEO_PCK_MAX, .n_ticks = 5, .format = "%.2f",
                         .label = "threshold on geodesic error / sqrt(area)"},
                        tcb_geo_pck_threshold, TCB_GEO_PCK_STEPS, TCB_M_GEO_AUC, geo_curve,
                        "method (AUC_geo %)", "geodesic PCK"};
    return plot(b, &p, path, err);
}
