/* PCK curves of one sequence, one line per method.
 *
 * x: threshold on the SQUARED distance, 0 … TCB_PCK_MAX (reference-protocol
 * §5.5); y: PCK in percent, always the full 0 … 100 so that plots of
 * different sequences compare at a glance. */
#include <string.h>

#include "reports/chart.h"
#include "reports/writers.h"

int tcb_rpt_plot_pck(const tcb_rpt_block *b, const char *path, tcb_error *err)
{
    const tcb_chart_axis x = {TCB_PCK_MAX, 5, "%.3f", "threshold on squared distance"};
    const tcb_chart_axis y = {100.0, 5, "%.0f", "PCK (%)"};
    tcb_chart c;
    tcb_chart_begin(&c, &x, &y);
    for (int k = 0; k < b->n_rows; k++) {
        const tcb_rpt_row *r = &b->rows[k];
        if (strcmp(r->status, "ok")) continue;
        tcb_chart_series_begin(&c, k);
        for (int s = 0; s < TCB_PCK_STEPS; s++) {
            double px = tcb_chart_px(&c, tcb_pck_threshold(s)), py = tcb_chart_py(&c, r->pck[s]);
            if (s == 0) cairo_move_to(c.cr, px, py);
            else cairo_line_to(c.cr, px, py);
        }
        cairo_stroke(c.cr);
        tcb_chart_series_end(&c);
    }
    tcb_chart_legend(&c, b, "method (AUC %)", TCB_M_AUC);
    tcb_chart_title(&c, b, "PCK");
    return tcb_chart_finish(&c, path, err);
}
