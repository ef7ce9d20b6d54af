/* PDG's deformation fields (github vc-bonn/preconditioned-deformation-grids
 * @ cf21c7d, src/optimization.py; the grids are vc-bonn/pcgrid @ 28a3b11,
 * src/pcgrid/grid.py): one field per frame transition g, the mean of
 * `levels` lattice levels (level l: r_l = 1 + 2l nodes per axis, 3 values a
 * node), moving a point x by
 *     y = x + 0.1 · tanh(s(x)),   s(x) = (1/L) Σ_l S_l(V_{g,l}, x)
 * with S_l the trilinear sample (neural/lattice.h). The released rotation
 * channels get an exactly zero gradient at their zero start and never move
 * (docs/protocol.md, "PDG"), so only the translation's 3 values are kept.
 *
 * The values are V_{g,l} = M_l⁻¹ U_{g,l} (neural/sobolev.h: pcgrid's
 * Laplacian 2D − A, λ_l = λ₀·growth^l; a one-node level has M = I). The
 * parameters U are one float vector, level-major: level l's block
 * [T][r_l³][3] at off[l], so one Adam group per level covers every
 * transition, as the reference's one Adam per level does.
 *
 *   tcb_pdg_fields_solve     V = M⁻¹ U, every level and transition (and
 *                            dU = M⁻¹ dV, the same call)
 *   tcb_pdg_field_forward    y [n][3] of points x [n][3] through field g
 *   tcb_pdg_field_backward   dV += and dx += from dy (the sample's
 *                            gradient in the points: a chain samples each
 *                            field where the previous one moved the points) */
#ifndef TCB_PDG_FIELD_H
#define TCB_PDG_FIELD_H

#include <stddef.h>

#include "neural/sobolev.h"
#include "tcb/error.h"

#define TCB_PDG_MAX_LEVELS 16
#define TCB_PDG_TSCALE 0.1f /* the translation's 0.1 · tanh */

typedef struct tcb_pdg_fields {
    int levels, T;
    int r[TCB_PDG_MAX_LEVELS];
    size_t off[TCB_PDG_MAX_LEVELS + 1]; /* level l's block [T][r_l³][3]; [levels] = the total */
    tcb_sobolev sobolev[TCB_PDG_MAX_LEVELS];
} tcb_pdg_fields;

/* T ≥ 1 transitions, 1 ≤ levels ≤ TCB_PDG_MAX_LEVELS, λ_l = lambda0 · growth^l. */
int tcb_pdg_fields_init(tcb_pdg_fields *f, int levels, int T, double lambda0, double growth, tcb_error *err);
void tcb_pdg_fields_free(tcb_pdg_fields *f);

/* Doubles of scratch tcb_pdg_fields_solve needs. */
size_t tcb_pdg_fields_scratch(const tcb_pdg_fields *f);

/* V [off[levels]] = M⁻¹ U (V may alias U). */
void tcb_pdg_fields_solve(const tcb_pdg_fields *f, const float *U, float *V, double *scratch);

/* The values of level l of field g inside V (or inside U, dV, dU). */
static inline const float *tcb_pdg_level(const tcb_pdg_fields *f, const float *V, int g, int l)
{
    return V + f->off[l] + (size_t)g * f->r[l] * f->r[l] * f->r[l] * 3;
}

/* s [n][3] (kept for the backward) and y [n][3] = x + 0.1 tanh(s) (y may
 * not alias x). */
void tcb_pdg_field_forward(const tcb_pdg_fields *f, const float *V, int g, const float *x, int n, float *s,
                           float *y);

/* From dy [n][3] = ∂ℓ/∂y: dV += ∂ℓ/∂V (field g's part); dx [n][3] += ∂ℓ/∂x
 * (the identity's dy plus the samples' dependence on x), skipped when dx
 * is NULL. ds [n][3] is scratch. */
void tcb_pdg_field_backward(const tcb_pdg_fields *f, const float *V, int g, const float *x, int n, const float *s,
                            const float *dy, float *dV, float *dx, float *ds);

#endif
