/* The robust two-way Chamfer of DynoSurf (github yaoyx689/DynoSurf,
 * code/loss.py), which Neu-PiG and PDG call too: between moved points
 * X [nx][3] and target points P [np][3], with s the SQUARED distance to the
 * nearest point of the other set,
 *     RC = Σ_{p∈P} w(s_p) s_p + Σ_{x∈X} w(s_x) s_x,   w(s) = exp(−s² / (2α²))
 * (sums, not means; the Welsch weight is applied to the squared distance
 * and held constant in the gradient, as the references detach it; α = 0.3
 * in all three). The gradient goes to X only: the targets are data. */
#ifndef TCB_NEURAL_ROBUST_CHAMFER_H
#define TCB_NEURAL_ROBUST_CHAMFER_H

#include "tcb/error.h"
#include "tcb/nn.h"

#define TCB_ROBUST_CHAMFER_ALPHA 0.3

/* *cd = RC(X, P); dX [nx][3] = ∂RC/∂X (overwrites). points_index indexes
 * P (tcb_nn_build over P); X's own index is built inside. */
int tcb_robust_chamfer(const float *X, int nx, const float *P, int np, const tcb_nn *points_index, double alpha,
                       double *cd, float *dX, tcb_error *err);

/* The same with DynoSurf's normal term beside it (code/loss.py L97-139):
 *   *normal = mean_{x∈X} (1 − |cos(n_x, n_p(x))|) + mean_{p∈P} (1 − |cos(n_p, n_x(p))|)
 * (neural/abs_cos.h) over the same nearest neighbours, its gradient in NX
 * [nx][3] into dNX (overwrites; NULL: none). NX and NP NULL: no normal
 * term, *normal (may be NULL) 0. */
int tcb_robust_chamfer_normals(const float *X, const float *NX, int nx, const float *P, const float *NP, int np,
                               const tcb_nn *points_index, double alpha, double *cd, double *normal, float *dX,
                               float *dNX, tcb_error *err);

#endif
