/* PDG's deformation fields (github vc-bonn/preconditioned-deformation-grids
 * @ cf21c7d, src/optimization.py; the grids are vc-bonn/pcgrid @ 28a3b11,
 * src/pcgrid/grid.py, value_wrapper.py, optimization_values.py): one field
 * per frame transition g, the mean of `levels` lattice levels (level l:
 * r_l = 1 + 2l nodes per axis, C values a node), s(x) = (1/L) Σ_l
 * S_l(V_{g,l}, x) with S_l the trilinear sample (neural/lattice.h), giving
 * a point the affine step [R | t], t = 0.1 · tanh(s_t(x)):
 *
 *   released  C = 3, s = s_t, R = I. The release's "Cayley" rotation
 *             (optimization_values.py:70-83) has an exactly zero gradient
 *             at its zero start, so its channels never move and it is the
 *             identity throughout (docs/protocol.md, "PDG"): only the
 *             translation's 3 values are kept, and y = x + t.
 *   cayley    C = 6, s = (r, s_t) as the release's channel order (rotation
 *             then translation: value_wrapper.py:189-196 with
 *             opt_run.py:187-190), R = (I − K)⁻¹(I + K), K = [r]× the
 *             cross-product matrix: a rotation for every r (by 2·atan|r|
 *             about r), about the cube's origin as the release's
 *             (optimization.py:96-101, 135-143).
 *
 * A chain composes the steps as the release's 4×4 accumulation per
 * template vertex (optimization.py:135-143): A^m = A^{m−1} · [R_m | t_m],
 * x^m = A^m x⁰, field m sampled at x^{m−1}. With R = I this is
 * x^m = x^{m−1} + t_m, which is all the released variant carries; the
 * cayley variant carries A (tcb_pdg_carry).
 *
 * The values are V_{g,l} = M_l⁻¹ U_{g,l} (neural/sobolev.h: pcgrid's
 * Laplacian 2D − A, λ_l = λ₀·growth^l; a one-node level has M = I), every
 * channel alike (the release's grids precondition all 6). The parameters
 * U are one float vector, level-major: level l's block [T][r_l³][C] at
 * off[l], so one Adam group per level covers every transition and
 * channel, as the reference's one Adam per level does.
 *
 *   tcb_pdg_fields_solve     V = M⁻¹ U, every level and transition (and
 *                            dU = M⁻¹ dV, the same call)
 *   tcb_pdg_cayley_forward   R [3][3] of r [3]
 *   tcb_pdg_cayley_backward  dr [3] from dR [3][3]
 *   tcb_pdg_field_forward    y [n][3] of points x [n][3] through field g
 *   tcb_pdg_field_backward   dV += and dx += from dy (the sample's
 *                            gradient in the points: a chain samples each
 *                            field where the previous one moved the
 *                            points), and the carry's dA += */
#ifndef TCB_PDG_FIELD_H
#define TCB_PDG_FIELD_H

#include <stddef.h>

#include "neural/sobolev.h"
#include "tcb/error.h"

#define TCB_PDG_MAX_LEVELS 16
#define TCB_PDG_TSCALE 0.1f /* the translation's 0.1 · tanh */
#define TCB_PDG_AFFINE 12   /* a carried transform [3][4], row-major [R | t] */

typedef enum tcb_pdg_rotation { TCB_PDG_RELEASED, TCB_PDG_CAYLEY } tcb_pdg_rotation;
extern const char *const tcb_pdg_rotation_names[]; /* {"released", "cayley", NULL} */

typedef struct tcb_pdg_fields {
    int levels, T;
    tcb_pdg_rotation rotation;
    int C;                      /* values a node: 3 (released), 6 (cayley: r, then the translation) */
    int r[TCB_PDG_MAX_LEVELS];
    size_t off[TCB_PDG_MAX_LEVELS + 1]; /* level l's block [T][r_l³][C]; [levels] = the total */
    tcb_sobolev sobolev[TCB_PDG_MAX_LEVELS];
} tcb_pdg_fields;

/* T ≥ 1 transitions, 1 ≤ levels ≤ TCB_PDG_MAX_LEVELS, λ_l = lambda0 · growth^l. */
int tcb_pdg_fields_init(tcb_pdg_fields *f, int levels, int T, tcb_pdg_rotation rotation, double lambda0,
                        double growth, tcb_error *err);
void tcb_pdg_fields_free(tcb_pdg_fields *f);

/* Doubles of scratch tcb_pdg_fields_solve needs. */
size_t tcb_pdg_fields_scratch(const tcb_pdg_fields *f);

/* V [off[levels]] = M⁻¹ U (V may alias U). */
void tcb_pdg_fields_solve(const tcb_pdg_fields *f, const float *U, float *V, double *scratch);

/* The values of level l of field g inside V (or inside U, dV, dU). */
static inline const float *tcb_pdg_level(const tcb_pdg_fields *f, const float *V, int g, int l)
{
    return V + f->off[l] + (size_t)g * f->r[l] * f->r[l] * f->r[l] * f->C;
}

/* R [3][3] row-major = (I − K)⁻¹(I + K), K = [r]× (K v = r × v). */
void tcb_pdg_cayley_forward(const float r[3], float R[9]);

/* dr [3] = ∂ℓ/∂r from dR [3][3] = ∂ℓ/∂R (overwrites). */
void tcb_pdg_cayley_backward(const float r[3], const float dR[9], float dr[3]);

/* The cayley variant's chain state over n points (x = A x0 per point):
 * the field's step is composed onto A, the moved point is y = A' x0. A
 * field called without a carry (the input term; every released call)
 * starts from the identity at x: y = R x + t. */
typedef struct tcb_pdg_carry {
    const float *x0;            /* [n][3] the points the chain started from */
    const float *A;             /* [n][12] the transform so far; NULL: the identity (x0 = x) */
    float *A_out;               /* [n][12] forward: A · [R | t]; NULL: not kept */
    const float *dA_out;        /* [n][12] backward: ∂ℓ/∂A_out from the later steps; NULL: none */
    float *dA;                  /* [n][12] backward: += ∂ℓ/∂A; NULL: not wanted (A is constant) */
} tcb_pdg_carry;

/* s [n][C] (kept for the backward) and y [n][3], the points x moved by
 * field g (y may not alias x). c: the cayley variant's carry, or NULL
 * (always NULL when released). */
void tcb_pdg_field_forward(const tcb_pdg_fields *f, const float *V, int g, const float *x, int n,
                           const tcb_pdg_carry *c, float *s, float *y);

/* From dy [n][3] = ∂ℓ/∂y (and c->dA_out): dV += ∂ℓ/∂V (field g's part);
 * dx [n][3] += ∂ℓ/∂x, skipped when dx is NULL — the samples' dependence
 * on x, plus y's own without a carry (with one, y depends on x0 and A,
 * not x); c->dA += ∂ℓ/∂A. ds [n][C] is scratch. */
void tcb_pdg_field_backward(const tcb_pdg_fields *f, const float *V, int g, const float *x, int n,
                            const tcb_pdg_carry *c, const float *s, const float *dy, float *dV, float *dx, float *ds);

#endif
