/* CC (Groueix et al., SGP'19, "Unsupervised cycle-consistent deformation
 * for shape matching"): the training losses of a batch of shape triplets
 * and their gradient with respect to the six deformations, as
 * training/triplet_point_cloud.py and auxiliary/useful_losses.py of
 * ThibaultGROUEIX/CycleConsistentDeformation compute them.
 *
 * Shapes 0, 1, 2 of a triplet are CC's P1, P2, P3. CC names a deformation
 * X_Y = "Y deformed towards X"; here D_k is the deformation of every point
 * of P_s towards P_t for the pair k = (s → t). */
#ifndef TCB_CC_LOSSES_H
#define TCB_CC_LOSSES_H

#include <stddef.h>
#include <stdint.h>

#include "tcb/error.h"

#define TCB_CC_PAIRS 6

/* {source, target} of pair k, in the order the CC trainer runs the network
 * (triplet_chamfer_loss), so D is laid out as CC produces it:
 *   k=0: 0→1 (P2_P1)  k=1: 1→0 (P1_P2)  k=2: 1→2 (P3_P2)
 *   k=3: 2→1 (P2_P3)  k=4: 2→0 (P1_P3)  k=5: 0→2 (P3_P1) */
extern const int tcb_cc_pairs[TCB_CC_PAIRS][2];

/* The k with tcb_cc_pairs[k] = {s, t}; −1 when s = t or s, t ∉ {0, 1, 2}. */
int tcb_cc_pair_index(int s, int t);

/* λ of each term; CC's defaults (argument_parser.py) are all 1. */
typedef struct tcb_cc_loss_weights {
    double lambda_chamfer, lambda_cycle2, lambda_cycle3;
} tcb_cc_loss_weights;

/* The unweighted terms, for logging, and total = Σ λ · term. */
typedef struct tcb_cc_loss_terms {
    double chamfer, cycle2, cycle3, total;
} tcb_cc_loss_terms;

/* Workspace for batches of up to max_batch triplets of n_points points
 * each: the nearest-neighbour maps, per-(pair, shape) partial sums and a
 * double gradient buffer, allocated once so that a training step allocates
 * nothing but tcb_nn's own index copies. Not shareable between threads. */
typedef struct tcb_cc_losses tcb_cc_losses;

int tcb_cc_losses_create(int max_batch, int n_points, tcb_cc_losses **out, tcb_error *err);
void tcb_cc_losses_free(tcb_cc_losses *ws);

/* Losses of B ≤ max_batch triplets:
 *   P [3][B][N][3]  the clouds P_0, P_1, P_2 (data: no gradient),
 *   D [6][B][N][3]  D_k, pair k as in tcb_cc_pairs; D_k[b][m] is point m
 *                   of P_s (shape b) deformed towards P_t,
 *   gD [6][B][N][3] or NULL: overwritten with ∂total/∂D.
 * N = n_points. All nearest-neighbour searches stay within one shape b
 * (CC's batch_idx offsets), exact via tcb_nn; with n_k(m) = NN in P_t of
 * D_k[b][m] (CC's idx1) and RMS(x, y) = √(mean over b, m, xyz of (x − y)²
 * + 1e-8) (CC's L2):
 *   chamfer = 1/6 Σ_k mean_{b, q ∈ P_t} min_m |D_k[b][m] − q|
 *             (CC's ASSYM_2: target → deformed only, not squared)
 *   cycle2  = 1/6 Σ_{k = s→t} RMS(D_{t→s}[b][n_k(m)], P_s[b][m])
 *   cycle3  = 1/6 Σ_{(i, j, l) permutations} RMS(D_{l→i}[b][n''(m)], P_i[b][m])
 *             with n' = n_{i→j}(m), n'' = n_{j→l}(n')
 * The NN indices are constants for the gradient (CC gathers with
 * `.data` indices): the cycle terms pull only the gathered D_{t→s},
 * D_{l→i} points, and the Chamfer term only the deformed point nearest to
 * each target point. Where that distance is exactly 0 its gradient is
 * taken as 0 (torch would give NaN there).
 * Deterministic, and bit-identical for any OpenMP thread count. Errors:
 * TCB_ERR_INPUT (bad arguments, B > max_batch), TCB_ERR_NUMERIC (a
 * non-finite or huge coordinate in P or D, from tcb_nn); gD and *terms
 * are then left untouched. */
int tcb_cc_losses_eval(tcb_cc_losses *ws, const float *P, const float *D, int B,
                       const tcb_cc_loss_weights *w, tcb_cc_loss_terms *terms, float *gD,
                       tcb_error *err);

/* n_k of the last eval, [B][N]: for point m of P_s in shape b, the index
 * in P_t of the target point nearest to D_k[b][m] (CC's idx1, without the
 * batch offset). NULL for a bad k, before any eval and after a failed one.
 * Valid until the next eval. */
const int32_t *tcb_cc_losses_matches(const tcb_cc_losses *ws, int k);

/* CC's L2 of the self-reconstruction term: √(mean_k (a_k − b_k)² + 1e-8)
 * over a, b [n] (0 when n = 0, as CC returns). grad_a [n] or NULL:
 * overwritten with ∂/∂a; b is a detached target. Non-finite input gives a
 * non-finite result: the caller checks. */
double tcb_cc_rms(const float *a, const float *b, size_t n, float *grad_a);

#endif
