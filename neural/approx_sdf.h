/* DynoSurf's approximate signed distance of a point to an oriented point
 * cloud (github yaoyx689/DynoSurf @ a2b7324, code/loss.py
 * approximate_sdf_loss L177-202 and calc_robust_sdf_sign_loss L234-266):
 * for a query y and its k nearest cloud points p_j with normals n_j,
 *   g_j = exp(−|y − p_j|² / r²),  w = softmax_j(g)   (a softmax of Gaussians,
 *        as the reference writes it: the weights stay within a factor e)
 *   s(y) = Σ_j w_j n_j · (y − p_j)       (positive on the normals' side)
 * The neighbours are found once per forward (no gradient through their
 * choice); the backward is exact in y:
 *   ∂s/∂y = Σ_j w_j n_j − (2/r²) Σ_j w_j g_j (l_j − s) (y − p_j),  l_j = n_j·(y − p_j).
 *
 * forward:  y [m][3], the cloud (index over p [N][3], normals [N][3])
 *           → s [m], and nbr [m][k] for the backward
 * backward: ds [m] → dy [m][3] (overwrites) */
#ifndef TCB_NEURAL_APPROX_SDF_H
#define TCB_NEURAL_APPROX_SDF_H

#include <stdint.h>

#include "tcb/error.h"
#include "tcb/nn.h"

#define TCB_APPROX_SDF_K 10
#define TCB_APPROX_SDF_K_MAX 64
#define TCB_APPROX_SDF_RADIUS 0.1

/* k in [1, TCB_APPROX_SDF_K_MAX] and at most N; fails when the search does
 * (non-finite queries). */
int tcb_approx_sdf_forward(float *s, int32_t *nbr, const float *y, int m, const tcb_nn *index, const float *p,
                           const float *normals, int k, double r, tcb_error *err);

void tcb_approx_sdf_backward(float *dy, const float *ds, const float *y, int m, const int32_t *nbr, const float *p,
                             const float *normals, int k, double r);

#endif
