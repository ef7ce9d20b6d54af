/* Points sampled on a triangle mesh with their face normals, and the
 * gradient back to the vertices: pytorch3d's sample_points_from_meshes
 * (pytorch3d/ops/sample_points_from_meshes.py, v0.7.4, return_normals=True)
 * as DynoSurf samples its extracted surfaces in both stages
 * (github yaoyx689/DynoSurf @ a2b7324, code/loss.py L88-94).
 *
 *   draw     face f ~ area (with replacement), u, v ~ U[0, 1);
 *            w = (1 − √u, √u (1 − v), √u v)   (uniform over the triangle)
 *   point    x = w0 a + w1 b + w2 c           (f = (a, b, c))
 *   normal   n = c_f / max(|c_f|, ε),  c_f = (b − a) × (c − b),  ε = FLT_EPSILON
 *
 * The draws are made once (no gradient through the choice of face); the
 * points and normals are differentiable in the vertices:
 *   ∂x/∂a = w0 I, …;  ∂n/∂c_f = (I − n nᵀ) / |c_f|;
 *   c_f = e1 × e2 (e1 = b − a, e2 = c − b): ∂L/∂e1 = e2 × g, ∂L/∂e2 = g × e1.
 *
 * Written by hand: the draw is a few lines over tcb_rng, and no kept C
 * library differentiates it. */
#ifndef TCB_NEURAL_MESH_SAMPLE_H
#define TCB_NEURAL_MESH_SAMPLE_H

#include <stdint.h>

#include "tcb/error.h"

struct tcb_rng;

typedef struct tcb_mesh_draw {
    int32_t face;
    float w[3]; /* barycentric weights of the face's vertices */
} tcb_mesh_draw;

/* m draws over the faces [nf][3] of verts; a mesh without area (or
 * non-finite) is TCB_ERR_NUMERIC. */
int tcb_mesh_sample_draw(const float *verts, const int32_t *faces, int nf, int m, struct tcb_rng *rng,
                         tcb_mesh_draw *draws, tcb_error *err);

/* pts [m][3] and normals [m][3] (may be NULL) of the draws. */
void tcb_mesh_sample_forward(const float *verts, const int32_t *faces, const tcb_mesh_draw *draws, int m, float *pts,
                             float *normals);

/* dverts [nv][3] += the gradient of the loss through the samples, given
 * ∂L/∂pts and ∂L/∂normals [m][3] (either may be NULL); face_grad [nf][3]
 * is scratch for the per-face normal gradient. */
void tcb_mesh_sample_backward(const float *verts, const int32_t *faces, int nf, const tcb_mesh_draw *draws, int m,
                              const float *dpts, const float *dnormals, float *face_grad, float *dverts);

#endif
