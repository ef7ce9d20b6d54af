/* Collapsed-patch detection of the evaluation (reference-protocol §5.3
 * item 2, as coded): patches whose squared area element vanishes are left
 * out of the second, denser pass. */
#ifndef TCB_ATLAS_COLLAPSE_H
#define TCB_ATLAS_COLLAPSE_H

#include "tcb/error.h"

/* phi_u, phi_v: [S][M][3], the tangents of the S shapes evaluated together
 * (S = 2: the two shapes of a pair) at the first pass's samples; patch p
 * owns samples [p·M/P, (p+1)·M/P), so M must be a multiple of P.
 *
 * Per shape and patch, Ap = mean over the patch's samples of EG − F² (the
 * SQUARED area element, unclamped); the patch is collapsed in that shape if
 * Ap / (mean_p Ap + 1e-30) < 1e-3. A patch is kept if it is not collapsed
 * in at least one shape; if that leaves none, all are kept.
 *
 * kept [P] gets the kept patch ids ascending, *n_kept their count P', and
 * *m_per_patch = floor(n_pts / P'), the second pass's samples per patch
 * (n_pts = 3125 in the protocol). */
int tcb_atlas_kept_patches(const float *phi_u, const float *phi_v, int S, int M, int P,
                           int n_pts, int *kept, int *n_kept, int *m_per_patch, tcb_error *err);

#endif
