/* The DSR regularizers as TCSR codes them (`loss_scaled_isometry`,
 * reference-protocol §3.3): scaled isometry plus a total-area cap. */
#ifndef TCB_ATLAS_LOSS_DSR_H
#define TCB_ATLAS_LOSS_DSR_H

#include "tcb/error.h"

typedef struct tcb_atlas_dsr_weights {
    double e, g, skew, stretch; /* α_E, α_G, α_skew, α_stretch */
    double total_area;          /* α_Atot */
} tcb_atlas_dsr_weights;

/* TCSR's values: α_E = α_G = α_skew = 1, α_stretch = 0, α_Atot = 100. */
tcb_atlas_dsr_weights tcb_atlas_dsr_defaults(void);

/* The unweighted terms, for logging. */
typedef struct tcb_atlas_dsr_terms {
    double e, g, skew, stretch, total_area;
} tcb_atlas_dsr_terms;

/* Per sample A² = max(EG − F², 0), A = √A², w = 1/(A² + 1e-20); μ_E, μ_G
 * are the means of E and G over the WHOLE batch (all B·M samples). Means
 * below are over all B·M samples:
 *   L_E       = mean (E − μ_E)² w        L_G       = mean (G − μ_G)² w
 *   L_skew    = mean F² w                L_stretch = mean (E − G)² w
 *   L_Atot    = mean_b max(0, Σ_p mean_{samples∈p} A − area_gt[b])²
 * phi_u, phi_v: [B][M][3]; patch p owns samples [p·M/P, (p+1)·M/P), so M
 * must be a multiple of P; area_gt: [B], the GT surface area of each
 * shape (already × TCSR's total_area_mult, which is 1).
 *
 * *loss = L_sciso = Σ α_k L_k (without `weight`; TCSR's total is
 * L_CD + α_sciso · L_sciso); terms (may be NULL) gets the unweighted L_k.
 * If dphi_u is not NULL (dphi_v then neither): dphi_u, dphi_v [B][M][3]
 * += weight · ∂L_sciso/∂φ_u, ∂L_sciso/∂φ_v, including the paths through
 * μ_E and μ_G. Where EG − F² ≤ 0 the clamp passes no gradient, and where
 * A = 0 the √ passes none (torch would give inf or NaN there; see
 * loss_dsr.c). A non-finite loss is TCB_ERR_NUMERIC. */
int tcb_atlas_dsr_loss(const float *phi_u, const float *phi_v, int B, int M, int P,
                       const double *area_gt, const tcb_atlas_dsr_weights *w, float weight,
                       double *loss, tcb_atlas_dsr_terms *terms, float *dphi_u, float *dphi_v,
                       tcb_error *err);

#endif
