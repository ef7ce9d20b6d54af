/* Neu-PiG's objective (github vc-bonn/neu-pig: src/utilities/loss_f.py,
 * src/loss_time_smoothing.py "pdg", src/optimization.py), one piece per
 * function, each with the gradient the training needs.
 *
 * Robust Chamfer of frame t, between the moved template X_t [nx][3] and the
 * frame's points P_t [np][3], with s the SQUARED nearest distance:
 *     CD_t = Σ_{p∈P_t} w(s_p) s_p + Σ_{x∈X_t} w(s_x) s_x,  w(s) = exp(−s² / (2α²)), α = 0.3
 * (sums, not means; the Welsch weight is applied to the squared distance
 * and held constant in the gradient, as the reference detaches it).
 *
 * Confidence of the frames ("pdg" time smoothing with "pdg" catch-up):
 * from the keyframe K outwards, c_K = 1 and
 *     c_t = c_{t∓1} · (1 / (1 + max(0, CD_t − CD_K)))^(1 − √(epoch / epochs)),
 * held constant; the Chamfer part of the loss is mean_t(c_t · CD_t).
 *
 * Isometry: weight · mean over frames and undirected edges of
 * |‖x_a − x_b‖ − ℓ_ab|, ℓ the template's edge lengths (weight 100). */
#ifndef TCB_NEUPIG_LOSS_H
#define TCB_NEUPIG_LOSS_H

#include <stdint.h>

#include "tcb/error.h"
#include "tcb/nn.h"

#define TCB_NEUPIG_WELSCH_ALPHA 0.3

/* *cd = CD of one frame; dX [nx][3] = ∂CD/∂X (overwrites). points_index
 * indexes P (tcb_nn_build over P). */
int tcb_neupig_chamfer(const float *X, int nx, const float *P, int np, const tcb_nn *points_index,
                       double alpha, double *cd, float *dX, tcb_error *err);

/* c [T] from the frames' CD [T], keyframe key, at epoch of epochs. */
void tcb_neupig_confidence(const double *cd, int T, int key, long long epoch, long long epochs,
                           double *c);

/* The isometry term of X [T][nv][3] over edges [ne][2] with template
 * lengths base [ne]; dX [T][nv][3] += its gradient (|·|' = sign, 0 at 0). */
double tcb_neupig_edge_l1(const float *X, int T, int nv, const int32_t *edges, int ne,
                          const float *base, double weight, float *dX);

#endif
