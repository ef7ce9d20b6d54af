/* Metric consistency between the two shapes of each pair (reference-
 * protocol §3.2), the loss that makes MCA's atlases temporally coherent. */
#ifndef TCB_ATLAS_LOSS_METRIC_H
#define TCB_ATLAS_LOSS_METRIC_H

#include "tcb/error.h"

/* L_mc = mean over the B/2 pairs (0,1), (2,3), … and the M samples of
 *     e = (E_a − E_b)² + 2 (F_a − F_b)² + (G_a − G_b)² = |g_a − g_b|²_F,
 * the two shapes compared at the same sample index (the batch shares its UV
 * samples). Patches partition the samples, so this is also the mean over
 * pairs × patches × per-patch samples. phi_u, phi_v: [B][M][3], B even.
 *
 * *loss = L_mc (without the weight). If dphi_u is not NULL (dphi_v then
 * neither): dphi_u, dphi_v [B][M][3] += weight · ∂L_mc/∂φ_u, ∂L_mc/∂φ_v.
 * A non-finite loss is TCB_ERR_NUMERIC. */
int tcb_atlas_metric_loss(const float *phi_u, const float *phi_v, int B, int M, float weight,
                          double *loss, float *dphi_u, float *dphi_v, tcb_error *err);

#endif
