/* Private to reports/: the frame every report plot shares, so that a plot
 * file only maps its data. A 900×600 PNG: axes from 0 with a light grid, a
 * legend panel right of the axes (it can never hide a curve), a title with
 * the block's role, pairs and seeds, and one style per method label that is
 * the same in every plot of a block and, unless two labels of a block would
 * share it, in every report (tcb_chart_styles).
 *
 * Use: tcb_chart_begin, then for each row tcb_chart_series_begin …
 * cairo drawing at (tcb_chart_px, tcb_chart_py) … tcb_chart_series_end,
 * then tcb_chart_legend, tcb_chart_title and tcb_chart_finish, which
 * publishes the file atomically and frees the chart whatever happened. */
#ifndef TCB_REPORTS_CHART_H
#define TCB_REPORTS_CHART_H

#include <cairo.h>

#include "reports/aggregate.h"
#include "tcb/error.h"

typedef struct tcb_chart_axis {
    double min, max;     /* the axis runs min … max (log: 0 < min) */
    int n_ticks;         /* linear: labelled ticks at min + (max − min)·k / n_ticks, k = 0 … n_ticks */
    const char *format;  /* printf format of a tick value ("%.3f"); 0 prints "0" */
    const char *label;
    int log;             /* logarithmic: a labelled tick at each power of ten, grid lines at 2× and 5× */
} tcb_chart_axis;

typedef struct tcb_chart {
    cairo_surface_t *surface;
    cairo_t *cr;
    tcb_chart_axis x, y;
    int n_rows;
    int *style;          /* malloc'ed [n_rows]: the rows' styles (tcb_chart_styles) */
} tcb_chart;

/* A white canvas with the axes drawn, and the styles of block b's rows
 * (b NULL: a plot of one series). */
void tcb_chart_begin(tcb_chart *c, const tcb_chart_axis *x, const tcb_chart_axis *y, const tcb_rpt_block *b);

/* Device coordinates of a data value. */
double tcb_chart_px(const tcb_chart *c, double x);
double tcb_chart_py(const tcb_chart *c, double y);

/* A method label's own style: colour index (style % 10) and dash pattern
 * (style / 10, solid first) of 40, a hash of the label alone, so that a
 * method keeps its colour in every plot of every report whatever rows are
 * added or removed. */
int tcb_chart_style_of(const char *label);

/* The styles of n distinct labels drawn together: each label's own style,
 * except that labels are taken in strcmp order and one whose colour (with
 * more than 10 labels: whose colour and dash) an earlier label holds takes
 * the next free one. So the labels of one plot never share a colour while
 * there are colours for all, and in a plot without a collision every label
 * has its own style. */
void tcb_chart_styles(const char *const *label, int n, int *style);

/* Clip to the plot area and take row k's colour, width and dash (k −1:
 * the one series of a plot begun without a block). */
void tcb_chart_series_begin(tcb_chart *c, int k);
void tcb_chart_series_end(tcb_chart *c);

/* One legend entry per row: "method (value)" with row r's mean of `metric`
 * for ok rows ("method (-)" when it has none), "method: status" in grey
 * otherwise. */
void tcb_chart_legend(tcb_chart *c, const tcb_rpt_block *b, const char *heading, int metric);

/* A title line and a grey subtitle line above the axes. */
void tcb_chart_headline(tcb_chart *c, const char *title, const char *subtitle);

/* tcb_chart_headline with "<what> — dataset / sequence" and the block's
 * role, pairs and seeds. */
void tcb_chart_title(tcb_chart *c, const tcb_rpt_block *b, const char *what);

/* A grey line of small print at the foot of the image, under the x axis's
 * label: how to read the plot. */
void tcb_chart_note(tcb_chart *c, const char *note);

/* Writes the PNG to a temporary beside `path` and renames it into place. */
int tcb_chart_finish(tcb_chart *c, const char *path, tcb_error *err);

/* "<prefix>_<dataset>_<sequence>.png" with characters outside
 * [A-Za-z0-9._-] as '_'. */
int tcb_chart_file_name(const tcb_rpt_block *b, const char *prefix, char *out, size_t size,
                        tcb_error *err);

/* The smallest of 1, 2, 2.5, 5 × 10^k that is ≥ v (v > 0): a round axis end. */
double tcb_chart_nice_ceil(double v);

#endif
