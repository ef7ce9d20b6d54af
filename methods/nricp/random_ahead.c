/* The random strategy's registrations, computed ahead of transfer in
 * parallel batches. One registration per pair is that strategy's whole
 * evaluation (about 1 500 s for 500 crane pairs on one thread), and the
 * harness asks for the pairs one at a time, so without this a cell's
 * threads idle but one. prepare_pairs says which pairs will come, in
 * which order; when transfer asks for the next of them, the batch that
 * starts there is registered at once over the cell's threads. Each
 * registration is deterministic and independent of the others, so the
 * results are the bits the one-at-a-time path (transfer of a pair it was
 * not told of) gives. */
#include <stdlib.h>
#include <string.h>

#include "methods/nricp/nricp_internal.h"

/* Pairs per batch and thread: enough to keep the threads busy while the
 * registrations' lengths vary, few enough that a stop request (seen by the
 * harness between transfers) waits for little. */
#define PAIRS_PER_THREAD 4

void nricp_ahead_free(nricp_ahead *a)
{
    free(a->pairs);
    free(a->outs);
    memset(a, 0, sizeof *a);
}

int nricp_ahead_announce(nricp_method *m, const int *pairs, int n, int threads, tcb_error *err)
{
    nricp_ahead *a = &m->ahead;
    nricp_ahead_free(a);
    if (n < 1) return TCB_OK;
    a->threads = threads > 0 ? threads : 1;
    a->cap = a->threads * PAIRS_PER_THREAD;
    a->pairs = malloc(2 * (size_t)n * sizeof *a->pairs);
    a->outs = malloc((size_t)a->cap * (size_t)m->n_verts * 3 * sizeof *a->outs);
    if (!a->pairs || !a->outs) {
        nricp_ahead_free(a);
        return tcb_fail(err, TCB_ERR_NOMEM, "nricp: out of memory for %d pairs' registrations", n);
    }
    memcpy(a->pairs, pairs, 2 * (size_t)n * sizeof *a->pairs);
    a->n = n;
    return TCB_OK;
}

/* Registers announced pairs first .. first + count − 1 into a->outs. */
static int register_batch(nricp_method *m, const tcb_sequence *seq, int first, int count, tcb_error *err)
{
    nricp_ahead *a = &m->ahead;
    tcb_error *errs = calloc((size_t)count, sizeof *errs);
    if (!errs) return tcb_fail(err, TCB_ERR_NOMEM, "nricp: out of memory");
    size_t frame = (size_t)m->n_verts * 3;
#pragma omp parallel for schedule(dynamic, 1) num_threads(a->threads)
    for (int b = 0; b < count; b++) {
        int i = a->pairs[2 * (first + b)], j = a->pairs[2 * (first + b) + 1];
        nricp_register(tcb_seq_frame(seq, i), nricp_normals_of(m, i), m->n_verts, tcb_seq_frame(seq, j),
                       nricp_normals_of(m, j), m->n_verts, &m->params, a->outs + (size_t)b * frame, &errs[b]);
    }
    int rc = TCB_OK;
    for (int b = 0; b < count && !rc; b++)
        if (errs[b].code) rc = tcb_fail(err, errs[b].code, "%s", errs[b].msg);
    free(errs);
    if (!rc) a->first = first, a->count = count;
    return rc;
}

int nricp_ahead_take(nricp_method *m, const tcb_sequence *seq, int i, int j, const float *src, float *out,
                     int *taken, tcb_error *err)
{
    nricp_ahead *a = &m->ahead;
    size_t frame = (size_t)m->n_verts * 3;
    *taken = 0;
    if (a->next >= a->n || a->pairs[2 * a->next] != i || a->pairs[2 * a->next + 1] != j ||
        memcmp(src, tcb_seq_frame(seq, i), frame * sizeof *src))
        return TCB_OK;
    if (a->next >= a->first + a->count) {
        int count = a->n - a->next < a->cap ? a->n - a->next : a->cap;
        int rc = register_batch(m, seq, a->next, count, err);
        if (rc) return rc;
    }
    memcpy(out, a->outs + (size_t)(a->next - a->first) * frame, frame * sizeof *out);
    a->next++;
    *taken = 1;
    return TCB_OK;
}
