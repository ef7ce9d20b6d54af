/* Normal-compatible k-NN over tcb_nn: fetch a block of plain nearest
 * candidates, keep the compatible ones in order, and re-query the queries
 * that came up short with a block GROWTH times larger, until the block is
 * the whole cloud. On a surface the nearest candidate is nearly always
 * compatible, so almost every query is settled by the first pass, which for
 * k = 1 is the cheaper tcb_nn_query1. */
#include "methods/nricp/knn_compat.h"

#include <stdlib.h>

#define FIRST_BLOCK 8 /* candidates per query in the first k-NN pass (at least 2k) */
#define GROWTH 4
/* Cap on queries × block held at once: a cloud whose normals all face away
 * from the queries needs block = n for every query. */
#define MAX_ENTRIES (1 << 22)

static inline int compatible(const float *a, const float *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2] >= 0.0f;
}

/* Keep the compatible candidates of one sorted row (length block) for query
 * q; returns how many were kept (≤ k). */
static int filter_row(const float *nrm, const float *qn, const int32_t *ridx, const float *rd2,
                      int block, int k, int32_t *idx, float *d2)
{
    int found = 0;
    for (int a = 0; a < block && found < k; a++) {
        if (!compatible(qn, nrm + 3 * (size_t)ridx[a])) continue;
        idx[found] = ridx[a];
        if (d2) d2[found] = rd2[a];
        found++;
    }
    for (int a = found; a < k; a++) {
        idx[a] = -1;
        if (d2) d2[a] = 0.0f;
    }
    return found;
}

/* One pass over the pending queries (ids pend[0..*np)) with `block`
 * candidates each; settled queries are removed from pend. */
static int pass(const tcb_nn *nn, const float *nrm, const float *qp, const float *qn, int k,
                int block, int32_t *pend, int *np, int32_t *idx, float *d2, int *cnt,
                tcb_error *err)
{
    int n = tcb_nn_size(nn);
    int chunk = MAX_ENTRIES / block > 0 ? MAX_ENTRIES / block : 1;
    if (chunk > *np) chunk = *np;
    float *buf = malloc((size_t)chunk * 3 * sizeof *buf);
    int32_t *ridx = malloc((size_t)chunk * block * sizeof *ridx);
    float *rd2 = malloc((size_t)chunk * block * sizeof *rd2);
    int rc = buf && ridx && rd2 ? TCB_OK : tcb_fail(err, TCB_ERR_NOMEM, "nricp: out of memory");
    int kept = 0;
    for (int start = 0; !rc && start < *np; start += chunk) {
        int m = *np - start < chunk ? *np - start : chunk;
        for (int t = 0; t < m; t++)
            for (int c = 0; c < 3; c++) buf[3 * t + c] = qp[3 * (size_t)pend[start + t] + c];
        rc = tcb_nn_queryk(nn, buf, m, block, ridx, rd2, err);
        for (int t = 0; !rc && t < m; t++) {
            int32_t q = pend[start + t];
            int found = filter_row(nrm, qn + 3 * (size_t)q, ridx + (size_t)t * block,
                                   rd2 + (size_t)t * block, block, k, idx + (size_t)q * k,
                                   d2 ? d2 + (size_t)q * k : NULL);
            cnt[q] = found;
            /* Writes trail reads, so compacting in place is safe. */
            if (found < k && block < n) pend[kept++] = q;
        }
    }
    *np = kept;
    free(buf), free(ridx), free(rd2);
    return rc;
}

/* k = 1 first pass: the plain nearest neighbour, kept when compatible. */
static int pass_nearest(const tcb_nn *nn, const float *nrm, const float *qp, const float *qn,
                        int nq, int32_t *pend, int *np, int32_t *idx, float *d2, int *cnt,
                        tcb_error *err)
{
    float *dist = d2 ? d2 : malloc((size_t)nq * sizeof *dist);
    if (!dist) return tcb_fail(err, TCB_ERR_NOMEM, "nricp: out of memory");
    int rc = tcb_nn_query1(nn, qp, nq, idx, dist, err);
    *np = 0;
    for (int q = 0; !rc && q < nq; q++) {
        cnt[q] = compatible(qn + 3 * (size_t)q, nrm + 3 * (size_t)idx[q]);
        if (!cnt[q]) {
            idx[q] = -1;
            dist[q] = 0.0f;
            pend[(*np)++] = q;
        }
    }
    if (!d2) free(dist);
    return rc;
}

int nricp_knn_compat(const tcb_nn *nn, const float *nrm, const float *qp, const float *qn,
                     int nq, int k, int32_t *idx, float *d2, int *cnt, tcb_error *err)
{
    int n = tcb_nn_size(nn);
    if (k < 1) return tcb_fail(err, TCB_ERR_INTERNAL, "nricp: k-NN with k = %d", k);
    if (nq <= 0) return TCB_OK;
    int32_t *pend = malloc((size_t)nq * sizeof *pend);
    if (!pend) return tcb_fail(err, TCB_ERR_NOMEM, "nricp: out of memory");
    int np = nq, rc = TCB_OK;
    int block = 2 * k > FIRST_BLOCK ? 2 * k : FIRST_BLOCK;
    if (k == 1) {
        rc = pass_nearest(nn, nrm, qp, qn, nq, pend, &np, idx, d2, cnt, err);
    } else {
        for (int q = 0; q < nq; q++) pend[q] = q;
    }
    for (;;) {
        if (block > n) block = n;
        if (rc || np == 0) break;
        rc = pass(nn, nrm, qp, qn, k, block, pend, &np, idx, d2, cnt, err);
        if (block == n) break;
        block *= GROWTH;
    }
    free(pend);
    return rc;
}
