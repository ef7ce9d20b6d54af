/* tcbench — triangle-mesh geometry: areas, normals, area-uniform sampling. */
#ifndef TCB_GEOMETRY_H
#define TCB_GEOMETRY_H

#include <stddef.h>
#include <stdint.h>

#include "tcb/error.h"
#include "tcb/rng.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Every x[k], k < n, is finite: what is checked of a method's points, a
 * cache's arrays, before they are used. */
int tcb_all_finite(const float *x, size_t n);
int tcb_all_finite_d(const double *x, size_t n);

double tcb_triangle_area(const float *a, const float *b, const float *c);

/* The axis-aligned box of n points [n][3]: box = [lo xyz, hi xyz]; and its
 * diagonal. */
void tcb_bbox(const float *points, size_t n, double box[6]);
double tcb_bbox_diag(const double box[6]);

/* Farthest-point sampling: idx[0] = start, then each next the point
 * farthest (in squared distance, float as the reference's tensors) from
 * those chosen, the first of equal maxima; k ≤ n. Fails only without
 * memory. DynoSurf's control points (its farthest_point_sample). */
int tcb_farthest_points(const float *pts, int n, int k, int start, int32_t *idx, tcb_error *err);

/* Sum of triangle areas; faces are [nf][3] vertex ids. */
double tcb_mesh_area(const float *verts, const int32_t *faces, int nf);

/* Area-weighted centroid of the surface (the expectation of an area-uniform sample). */
void tcb_surface_centroid(const float *verts, const int32_t *faces, int nf, double c[3]);

/* Area-weighted vertex normals, unit length; zero for vertices on no
 * non-degenerate face. normals is [nv][3]. */
void tcb_vertex_normals(const float *verts, int nv, const int32_t *faces, int nf,
                        float *normals);

/* n samples uniform over the surface area (face by area, then a uniform
 * barycentric point: the PyTorch3D sample_points_from_meshes scheme).
 * out is [n][3]. Fails on a zero-area mesh. */
int tcb_sample_surface(const float *verts, const int32_t *faces, int nf, int n,
                       tcb_rng *rng, float *out, tcb_error *err);
/* The same, and face_of[s] (when not NULL, [n]) the face sample s lies on:
 * the same draws, so the same points for the same stream. */
int tcb_sample_surface_faces(const float *verts, const int32_t *faces, int nf, int n,
                             tcb_rng *rng, float *out, int32_t *face_of, tcb_error *err);

/* The unit normal of triangle face ((b − a) × (c − a), corners in order);
 * zero for a degenerate one. */
void tcb_face_normal(const float *verts, const int32_t *face, float out[3]);

#ifdef __cplusplus
}
#endif
#endif
