/* PDG's objective for one epoch (github vc-bonn/preconditioned-deformation-
 * grids @ cf21c7d, src/optimization.py; docs/protocol.md, "PDG"), with its
 * gradient in the fields' values.
 *
 * n frames, keyframe K, T = n − 1 transitions; transition g relates frames
 * g and g + 1 and points away from the keyframe: field g moves frame g + 1
 * onto frame g when g < K, frame g onto frame g + 1 otherwise.
 *
 *   input term   L_in = (1/T) Σ_g RC(field_g(P_src(g)), P_dst(g))
 *   the chain    from the template v (held constant) outward both ways:
 *                x⁰ = v, x^m = field_{g_m}(x^{m−1}) (with the cayley
 *                rotation x^m = A^m v, A^m = A^{m−1}·[R_m | t_m] sampled
 *                at x^{m−1}: methods/pdg/field.h), the backward chain
 *                through fields K−1, K−2, … onto frames K−1, K−2, …, the
 *                forward chain through fields K, K+1, … onto frames K+1, …;
 *                each field is sampled where the previous ones moved the
 *                points, so the gradient flows back along the chain
 *   prediction   L_pred = (1/M) Σ_{m=1..M} c_m · CD_m, M the longer
 *                chain's length, CD_m the mean over the chains still going
 *                of RC(x^m, the frame they reach), and the catch-up weights
 *                c_m = s_m^e, e = 1 − √(epoch/epochs), s_1 = 1,
 *                s_{m+1} = s_m / max(1, 1 + Σ_{j≤m} c_j CD_j − L_in),
 *                held constant (detached)
 *   edges        L_edge = w_e · (1/M) Σ_m mean over the live chains and the
 *                template's edges of |ℓ_e(x^m) − ℓ_e(x^{m−1})| (w_e = 250)
 * The loss is L_in during the warm-up (epoch < warmup: 101) and
 * L_in + L_pred + L_edge after it. RC is the robust Chamfer
 * (neural/robust_chamfer.h). */
#ifndef TCB_PDG_OBJECTIVE_H
#define TCB_PDG_OBJECTIVE_H

#include <stdint.h>

#include "methods/pdg/field.h"
#include "tcb/error.h"
#include "tcb/nn.h"

typedef struct tcb_pdg_problem {
    int n, key;                          /* frames, keyframe */
    const float *const *points;          /* [n] → [n_points[t]][3], in the fields' cube */
    const int *n_points;
    const tcb_nn *const *points_index;   /* [n] */
    int nv;
    const float *template_verts;         /* [nv][3] v, the chain's start */
    int ne;
    const int32_t *edges;                /* [ne][2] the template's undirected edges */
    const float *template_edge_len;      /* [ne] ℓ_e(v) */
} tcb_pdg_problem;

typedef struct tcb_pdg_weights {
    double edge;           /* w_e: 250 */
    double alpha;          /* the robust Chamfer's α: 0.3 */
    long long warmup;      /* epochs on L_in alone: 101 */
} tcb_pdg_weights;

typedef struct tcb_pdg_loss {
    double total, input, pred, edge;
} tcb_pdg_loss;

/* The loss at epoch (of epochs) and dV [f->off[f->levels]] = ∂loss/∂V
 * (overwrites). */
int tcb_pdg_loss_grad(const tcb_pdg_fields *f, const float *V, const tcb_pdg_problem *p, const tcb_pdg_weights *w,
                      long long epoch, long long epochs, tcb_pdg_loss *out, float *dV, tcb_error *err);

/* X [n][nv][3]: the template carried into every frame by the chains
 * (X[K] = v): the fitted meshes. */
int tcb_pdg_propagate(const tcb_pdg_fields *f, const float *V, const tcb_pdg_problem *p, float *X, tcb_error *err);

#endif
