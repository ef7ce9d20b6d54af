/* Vertex colours for the meshes `tcbench inspect` writes. Private to
 * views/. */
#ifndef TCB_VIEWS_COLORMAP_H
#define TCB_VIEWS_COLORMAP_H

#include <stdint.h>

/* rgb [n][3]: each vertex coloured by its position in `ref` [n][3] (the
 * sequence's first frame), x, y, z → red, green, blue over ref's bounding
 * box, lifted off black. A colour then names a place on the body in every
 * frame, so a correct correspondence carries colours unchanged. */
void tcb_color_by_position(const float *ref, int n, uint8_t *rgb);

/* rgb [3]: the viridis colour of err / err_max, clamped to [0, 1] (dark
 * violet for 0, yellow at and beyond err_max). */
void tcb_color_by_error(double err, double err_max, uint8_t *rgb);

#endif
