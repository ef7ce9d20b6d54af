/* Neu-PiG's objective (github vc-bonn/neu-pig: src/utilities/loss_f.py,
 * src/loss_time_smoothing.py "pdg", src/optimization.py), one piece per
 * function, each with the gradient the training needs.
 *
 * The Chamfer of frame t, CD_t, is the robust Chamfer between the moved
 * template and the frame's points (neural/robust_chamfer.h).
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

/* c [T] from the frames' CD [T], keyframe key, at epoch of epochs. */
void tcb_neupig_confidence(const double *cd, int T, int key, long long epoch, long long epochs,
                           double *c);

/* The isometry term of X [T][nv][3] over edges [ne][2] with template
 * lengths base [ne]; dX [T][nv][3] += its gradient (|·|' = sign, 0 at 0). */
double tcb_neupig_edge_l1(const float *X, int T, int nv, const int32_t *edges, int ne,
                          const float *base, double weight, float *dX);

#endif
