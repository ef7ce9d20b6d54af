/* The checkerboard texture of `tcbench frames` (tcb/frames.h). Private to
 * views/.
 *
 * One image serves every chart of a tcb_uv_mesh and every frame: chart c's
 * unit square sits in cell c of a grid (cols x rows, row 0 at the top),
 * inset by a gutter that repeats the square's edge colour, so a viewer's
 * texture filtering never bleeds one chart into its neighbour. Each square
 * shows CHECKS x CHECKS checks in a light and a dark tone of the chart's own
 * hue (hues spread by the golden ratio, so charts with neighbouring numbers
 * differ most), the check at the chart's (u, v) origin white so a mirrored
 * or turned chart shows it. */
#ifndef TCB_VIEWS_CHECKER_H
#define TCB_VIEWS_CHECKER_H

#include <stdint.h>

#include "tcb/error.h"

#define TCB_CHECKER_CELL 256   /* texture pixels per chart's cell */
#define TCB_CHECKER_GUTTER 8   /* pixels of each cell's border outside the square */
#define TCB_CHECKER_CHECKS 8   /* checks per side of a chart */

typedef struct tcb_checker {
    int n_charts, cols, rows; /* the image is cols x rows cells */
} tcb_checker;

/* The nearest-square grid for n_charts >= 1 charts. */
tcb_checker tcb_checker_layout(int n_charts);

/* The colour of chart `chart` at (u, v) in [0,1]^2 (clamped). */
void tcb_checker_color(const tcb_checker *c, int chart, double u, double v, uint8_t rgb[3]);

/* (u, v) of a chart as OBJ texture coordinates of the image, vt[2] in
 * [0,1]^2 with v = 0 at the image's bottom row. */
void tcb_checker_texcoord(const tcb_checker *c, int chart, double u, double v, float vt[2]);

/* The image as a PNG, written atomically. */
int tcb_checker_write_png(const tcb_checker *c, const char *path, tcb_error *err);

#endif
