/* Normal-compatible exact k-NN (reference-protocol §6.2, step 1).
 *
 * Every nearest-neighbour query of Thea's Register sees only candidates
 * whose normal does not face away from the query's: n_query · n_cand ≥ 0.
 * This keeps a point on the front of a thin part (an ear, a leg) from
 * snapping to the back of it. */
#ifndef TCB_NRICP_KNN_COMPAT_H
#define TCB_NRICP_KNN_COMPAT_H

#include <stdint.h>

#include "tcb/error.h"
#include "tcb/nn.h"

/* For each of nq queries (position qp[q], normal qn[q]; both [nq][3]): the
 * k nearest points of `nn` whose normal nrm[c] ([size(nn)][3]) satisfies
 * qn[q] · nrm[c] ≥ 0, in tcb_nn_queryk's (d², index) order. Exact: they
 * are the first k compatible entries of the full sorted candidate list.
 * idx is [nq][k]; cnt[q] ≤ k is how many were found (fewer only when fewer
 * compatible points exist; unused slots are -1). d2 ([nq][k]) may be NULL. */
int nricp_knn_compat(const tcb_nn *nn, const float *nrm, const float *qp, const float *qn,
                     int nq, int k, int32_t *idx, float *d2, int *cnt, tcb_error *err);

#endif
