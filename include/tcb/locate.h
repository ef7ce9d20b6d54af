/* tcbench — points on a triangle mesh by face and barycentric coordinates.
 *
 * The read-out of methods whose frames share one triangulation (Neu-PiG's
 * deformed template): a source point is located on frame i's mesh (its
 * closest surface point) and carried to the same barycentric point of the
 * same face on frame j's mesh. Barycentric coordinates are invariant under
 * affine maps, so a frame that is an affine image of another carries every
 * point to its image. */
#ifndef TCB_LOCATE_H
#define TCB_LOCATE_H

#include <stdint.h>

#include "tcb/error.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct tcb_surface_point {
    int32_t face;   /* index into the faces */
    float bary[3];  /* weights of the face's three vertices: ≥ 0, sum 1 */
} tcb_surface_point;

/* For each of nq queries, the closest point of the surface (verts [nv][3],
 * faces [nf][3]) — exact, not the closest vertex, exact ties to the lowest
 * face index: faces are pruned by the distance of their centroids, bounded
 * by the largest vertex-to-centroid radius among faces of their size class.
 * dist2 [nq] (may be NULL) receives the squared distance. Fails on
 * an empty mesh, face indices outside [0, nv) and non-finite coordinates. */
int tcb_mesh_locate(const float *verts, int nv, const int32_t *faces, int nf, const float *queries, int nq,
                    tcb_surface_point *out, float *dist2, tcb_error *err);

/* The points loc[0..n) on a mesh with the same faces and vertices verts:
 * out [n][3]. The caller guarantees the faces index verts. */
void tcb_surface_points(const float *verts, const int32_t *faces, const tcb_surface_point *loc, int n,
                        float *out);

#ifdef __cplusplus
}
#endif
#endif
