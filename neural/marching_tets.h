/* Marching tetrahedra (Doi & Koide 1991) as DynoSurf extracts its template
 * from an SDF on a tetrahedral grid: kaolin's `marching_tetrahedra`
 * (kaolin/ops/conversions/tetmesh.py, v0.14), reproduced in its output
 * order so that a surface can be compared vertex for vertex.
 *
 *   occupied      s_i > 0 (DynoSurf's SDF is positive outside)
 *   crossing edge (a, b), a < b, one end occupied: one surface vertex
 *                 v = (s_a x_b − s_b x_a) / (s_a − s_b), made once and
 *                 shared by every tet around the edge (a watertight mesh)
 *   vertex order  the crossing edges in lexicographic (a, b) order
 *   face order    the tets with one triangle, then those with two, each
 *                 group in tet order; triangles from kaolin's 16-case table
 *                 (a positively oriented tet gives normals toward s > 0)
 *
 * forward:  x [nv][3] grid positions, s [nv] values, tets [nt][4]
 *           → surface verts [n][3], faces [m][3], edges [n][2]
 * backward: dverts [n][3] → dx [nv][3] and ds [nv], accumulated (+=):
 *           ∂v/∂x_a = −s_b/D, ∂v/∂x_b = s_a/D,
 *           ∂v/∂s_a = (x_b − v)/D, ∂v/∂s_b = (v − x_a)/D, D = s_a − s_b.
 *
 * Written by hand: no kept C or C++ library extracts an isosurface from
 * values on an arbitrary tetrahedral mesh with its gradient (CGAL's and
 * VTK's contouring give no derivatives, and neither kaolin's order). */
#ifndef TCB_NEURAL_MARCHING_TETS_H
#define TCB_NEURAL_MARCHING_TETS_H

#include <stdint.h>

#include "tcb/error.h"

typedef struct tcb_mt_surface {
    int n_verts;
    int n_faces;
    float *verts;    /* [n_verts][3] */
    int32_t *faces;  /* [n_faces][3] */
    int32_t *edges;  /* [n_verts][2]: the grid edge (a < b) each vertex lies on */
} tcb_mt_surface;

void tcb_mt_surface_free(tcb_mt_surface *s);

/* The s = 0 surface of the grid; an empty surface (no tet crosses zero)
 * is a success with n_verts = n_faces = 0. Tets naming a vertex outside
 * [0, nv) are TCB_ERR_INPUT. */
int tcb_marching_tets_forward(const float *x, const float *s, int nv, const int32_t *tets, int nt,
                              tcb_mt_surface *out, tcb_error *err);

/* The gradient of a loss through the surface's vertex positions. */
void tcb_marching_tets_backward(const float *x, const float *s, const tcb_mt_surface *surf,
                                const float *dverts, float *dx, float *ds);

#endif
