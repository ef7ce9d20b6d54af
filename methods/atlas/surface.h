/* The atlas as a textured mesh (the method table's `surface`, for
 * `tcbench frames`): every patch's unit square sampled on a regular grid,
 * two triangles per grid cell, decoded for one frame's input cloud. */
#ifndef TCB_ATLAS_SURFACE_H
#define TCB_ATLAS_SURFACE_H

#include "methods/atlas/model.h"
#include "tcb/method.h"

/* Vertices per side of a patch's grid: 24 x 24 cells, so the harness's
 * 8 x 8 checks per patch each cover 3 x 3 whole cells and their edges run
 * along triangle edges (a face never straddles two checks). */
#define TCB_ATLAS_SURFACE_RES 25

/* The grid of P patches with res x res vertices each (res >= 2): chart,
 * uv and faces of *out, verts left NULL. Vertex p res^2 + r res + c is
 * patch p at (u, v) = (c, r) / (res - 1); faces counter-clockwise in
 * (u, v), 2 (res - 1)^2 per patch, in patch order. */
int tcb_atlas_uv_grid(int P, int res, tcb_uv_mesh *out, tcb_error *err);

/* The grid decoded for cloud [N][3] (one frame's input points) by model m:
 * *out complete. On failure *out is freed. */
int tcb_atlas_surface(const tcb_atlas_model *m, const float *cloud, int N, int res, tcb_uv_mesh *out,
                      tcb_error *err);

#endif
