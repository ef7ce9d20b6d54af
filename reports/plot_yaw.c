/* The yaw the rotation alignment chose for each frame (tcb/align.h), as
 * `tcbench datasets align --plot` draws it: one dot per frame joined by a
 * line, in (−180°, 180°], so that a small turn either way reads as small
 * (−3° is drawn as −3°, not as 357°). A subject turning steadily reads as
 * a ramp that wraps at ±180°; isolated spikes are frames the Chamfer
 * matched facing another way. */
#include <math.h>
#include <stdio.h>

#include "reports/chart.h"
#include "tcb/align.h"
#include "tcb/report.h"

/* Step s of TCB_ALIGN_STEPS as degrees in (−180, 180]. */
static double yaw_degrees(int s)
{
    double d = fmod(s * (360.0 / TCB_ALIGN_STEPS), 360.0);
    if (d < 0) d += 360.0;
    return d > 180.0 ? d - 360.0 : d;
}

int tcb_plot_yaw(const char *path, const char *sequence, const int *step, int n_frames, int samples,
                 tcb_error *err)
{
    int last = n_frames > 1 ? n_frames - 1 : 1;
    int xstep = (int)tcb_chart_nice_ceil(ceil(last / 10.0));
    int n_x = (last + xstep - 1) / xstep;
    const tcb_chart_axis x = {.max = (double)n_x * xstep, .n_ticks = n_x, .format = "%.0f", .label = "frame"};
    const tcb_chart_axis y = {.min = -180.0, .max = 180.0, .n_ticks = 6, .format = "%.0f",
                              .label = "yaw (degrees about y)"};
    tcb_chart c;
    tcb_chart_begin(&c, &x, &y, NULL);
    tcb_chart_series_begin(&c, -1);
    for (int f = 0; f < n_frames; f++) {
        double px = tcb_chart_px(&c, f), py = tcb_chart_py(&c, yaw_degrees(step[f]));
        /* a jump of more than half a turn is a wrap through ±180°, not a swing */
        if (f == 0 || fabs(yaw_degrees(step[f]) - yaw_degrees(step[f - 1])) > 180.0) cairo_move_to(c.cr, px, py);
        else cairo_line_to(c.cr, px, py);
    }
    cairo_stroke(c.cr);
    for (int f = 0; f < n_frames; f++) {
        cairo_arc(c.cr, tcb_chart_px(&c, f), tcb_chart_py(&c, yaw_degrees(step[f])), 2.5, 0.0, 2.0 * M_PI);
        cairo_fill(c.cr);
    }
    tcb_chart_series_end(&c);
    char title[256], sub[256];
    snprintf(title, sizeof title, "rotation alignment — %s", sequence);
    snprintf(sub, sizeof sub, "%d frames · %d steps of %.0f° · Chamfer on %d points per frame", n_frames,
             TCB_ALIGN_STEPS, 360.0 / TCB_ALIGN_STEPS, samples);
    tcb_chart_headline(&c, title, sub);
    return tcb_chart_finish(&c, path, err);
}
