/* DynoSurf's frame, keyframe and tetrahedral grid (github yaoyx689/DynoSurf
 * @ a2b7324: code/dataset.py normalize_seq and select_minchamfer_idx,
 * code/utils/tet_utils.py build_tet_grid and calc_tet_edge_length,
 * confs/base.conf).
 *
 * Frame: p' = (p − m) / d, m the mean of frame 0's points and d the
 *   diagonal of their bounding box, for every frame.
 * Keyframe: the frame t minimising the mean over all frames u (t itself
 *   included) of D(t, u) = Σ_{p ∈ P_t} min_q |p − q|² + Σ_{q ∈ P_u} min_p |q − p|²
 *   (sums of squared distances, pytorch3d's knn_points); the first of equal
 *   minima.
 * Grid: the keyframe's convex hull grown by 0.1 (tcb_convex_offset),
 *   remeshed isotropically toward 1 % of the grown shell's box diagonal in
 *   3 rounds (MeshLab's defaults, which the reference leaves), and filled by
 *   TetGen with tets of at most 4.5e-7 in volume and radius-edge 2
 *   (tcb_tetrahedralize), all in the normalised frame. docs/meshing.md
 *   names what differs from the reference's MeshLab steps.
 * Edge bound: the grid's shortest tet edge, or its mean edge when the
 *   shortest is below 1e-4 (calc_tet_edge_length): the scale of the shape
 *   network's vertex offsets. */
#ifndef TCB_DYNOSURF_GRID_H
#define TCB_DYNOSURF_GRID_H

#include "tcb/error.h"
#include "tcb/mesh.h"
#include "tcb/tetmesh.h"

#define DYNO_SHELL_OFFSET 0.1
#define DYNO_REMESH_FRACTION 0.01
#define DYNO_REMESH_ITERATIONS 3
#define DYNO_TET_RADIUS_EDGE 2.0
#define DYNO_TET_VOLUME 4.5e-7 /* confs/base.conf tet_grid_volume */

typedef struct dyno_frame {
    double mean[3];
    double diag;  /* p' = (p − mean) / diag */
} dyno_frame;

/* The frame of frame 0's points [n][3]; an error when they are not finite
 * or all the same. */
int dyno_frame_of(const float *pts0, int n, dyno_frame *f, tcb_error *err);

/* The frame of the first of T clouds as the pcgrid read-out's map
 * (methods/pcgrid/fitted.h: centre the mean, scale 1/diag). */
struct tcb_pcgrid_frame_map;
int dyno_frame_map(const float *const *clouds, const int *n, int T, struct tcb_pcgrid_frame_map *map, tcb_error *err);

/* out [n][3] = the frame applied to pts [n][3] (may alias). */
void dyno_map_points(const dyno_frame *f, const float *pts, int n, float *out);

/* The keyframe of T frames of points points[t] [n[t]][3] (normalised). */
int dyno_keyframe(const float *const *points, const int *n, int T, int *key, tcb_error *err);

/* The grid around the keyframe's normalised points [n][3], with the hull
 * (DynoSurf's SDF pretraining target) and the shell that was filled;
 * max_volume is DYNO_TET_VOLUME and remesh DYNO_REMESH_FRACTION (of the
 * shell's box diagonal) at the reference's resolution (the `cpu` and
 * `tiny` presets coarsen them). */
int dyno_grid_build(const float *pts, int n, double max_volume, double remesh, tcb_mesh *hull, tcb_mesh *shell,
                    tcb_tetmesh *grid, tcb_error *err);

/* calc_tet_edge_length: the shortest of every tet's six edges, or the
 * mean edge when that is below 1e-4. */
double dyno_tet_edge_bound(const tcb_tetmesh *grid);

#endif
