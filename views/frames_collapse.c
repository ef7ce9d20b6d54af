/* Collapsed patches of a drawn surface (views/frames_style.h): an atlas
 * whose training shrank a patch to a sliver or a point draws it as one,
 * which a reader of the strip cannot tell from a small patch; this says it. */
#include <stdlib.h>

#include "tcb/geometry.h"
#include "views/frames_style.h"

int tcb_frames_collapsed(const tcb_uv_mesh *m, double gt_area, unsigned char *collapsed, int *n, tcb_error *err)
{
    *n = 0;
    if (m->n_charts == 0) return TCB_OK; /* a mesh without charts has no patches to collapse */
    double *area = calloc((size_t)m->n_charts, sizeof *area);
    if (!area) return tcb_fail(err, TCB_ERR_NOMEM, "out of memory for %d charts", m->n_charts);
    for (size_t t = 0; t < (size_t)m->n_faces; t++) {
        const int32_t *v = m->faces + 3 * t;
        area[m->chart[v[0]]] += tcb_triangle_area(m->verts + 3 * (size_t)v[0], m->verts + 3 * (size_t)v[1],
                                                  m->verts + 3 * (size_t)v[2]);
    }
    for (int c = 0; c < m->n_charts; c++) *n += collapsed[c] = area[c] < TCB_FRAMES_COLLAPSED * gt_area / m->n_charts;
    free(area);
    return TCB_OK;
}
