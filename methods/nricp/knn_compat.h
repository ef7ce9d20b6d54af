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

/* An index over points with normals; it keeps a copy of both. */
typedef struct nricp_compat_index nricp_compat_index;

/* Index n points (pts, nrm: [n][3], finite; n ≥ 1). */
int nricp_compat_build(const float *pts, const float *nrm, int n, nricp_compat_index **out, tcb_error *err);
void nricp_compat_free(nricp_compat_index *ix);

/* Move the indexed points to pts ([n][3], the caller's order; finite):
 * the normals and the tree stay, its boxes are refitted. Searches stay
 * exact — a tree split for other positions only prunes less — and a move
 * costs O(n) against a build's O(n log n): for a cloud that moves a little
 * at a time, as a registration's deformed target does round by round. */
void nricp_compat_move(nricp_compat_index *ix, const float *pts);

/* For each of nq queries (position qp[q], normal qn[q]; both [nq][3]): the
 * k nearest indexed points whose normal nrm[c] satisfies qn[q] · nrm[c] ≥ 0
 * (in float, summed x, y, z), ordered by (d², index), d² the float
 * (dx² + dy²) + dz². Exact: the first k compatible entries of the whole
 * cloud sorted that way. idx is [nq][k]; cnt[q] ≤ k is how many were found
 * (fewer only when fewer compatible points exist; unused slots are -1).
 * d2 ([nq][k]) may be NULL. */
int nricp_knn_compat(const nricp_compat_index *ix, const float *qp, const float *qn, int nq, int k,
                     int32_t *idx, float *d2, int *cnt, tcb_error *err);

#endif
