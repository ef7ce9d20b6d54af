/* The training Chamfer loss of the atlas family (reference-protocol §3.1). */
#ifndef TCB_ATLAS_LOSS_CHAMFER_H
#define TCB_ATLAS_LOSS_CHAMFER_H

#include "tcb/error.h"

/* L_CD = mean_{b,m} min_n |p̂_bm − p_bn|² + mean_{b,n} min_m |p̂_bm − p_bn|²
 * over a batch of B shapes: pred [B][M][3] predicted points p̂ (all patches,
 * collapsed ones included), target [B][N][3] input points p. Squared
 * distances; each term is a mean over all B·M resp. B·N points.
 *
 * *loss = L_CD (without the weight). If dpred is not NULL,
 * dpred [B][M][3] += weight · ∂L_CD/∂p̂ (accumulated, so the caller zeroes it
 * once per step). The gradient flows through each point's nearest
 * neighbour only, as torch's argmin-then-recompute does; neighbours come
 * from the exact k-NN (tcb/nn.h), exact ties go to the lowest index as
 * torch's argmin does. Non-finite points are TCB_ERR_NUMERIC. */
int tcb_atlas_chamfer_loss(const float *pred, const float *target, int B, int M, int N,
                           float weight, double *loss, float *dpred, tcb_error *err);

#endif
