/* propagate_deform (reference-protocol §6.3; TCSR's propagate_noproj):
 * X ← ν_{P_{k±1}}(X) from frame i through every frame up to j, X starting
 * as P_i with the normals of frame i throughout (Thea writes the original
 * normals back).
 *
 * A pair costs |i − j| registrations, (F + 1) / 3 on average: 29 576 for
 * crane's 500 pairs, ≈ 9 h on one core. Pairs that leave the same frame in
 * the same direction share their chain up to the nearer target (X after k
 * steps does not depend on where the chain ends), so prepare_pairs runs
 * one chain per (source, direction) to its farthest target and keeps X as
 * it passes each target: 16 817 registrations on crane, with the same bits
 * as one chain per pair (every step is the same deterministic registration
 * of the same inputs). The chains are independent: they run in parallel,
 * the longest first, and each finished one is saved in the cell's work
 * directory (deform_store.c), so a stopped or killed evaluation continues
 * where it was. A pair transferred without being announced runs its own
 * chain. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "methods/nricp/deform_cost.h"
#include "methods/nricp/nricp_internal.h"
#include "tcb/fsutil.h"

/* ---- one chain ---------------------------------------------------------- */

/* Counts registrations for the progress bar; NULL in a lone transfer. */
typedef struct chain_watch {
    const tcb_fit_ctx *ctx;
    int done, total;
} chain_watch;

static void count_step(chain_watch *w)
{
    if (!w) return;
#pragma omp critical(nricp_deform_progress)
    tcb_report_progress(&w->ctx->reporter, ++w->done, w->total, "nricp: deform chains");
}

static int stop_requested(const chain_watch *w) { return w && tcb_fit_interrupted(w->ctx); }

/* Runs c from x0 (the points of frame c->source) to its last target,
 * writing X into c->outs at each target. A stop request ends it between
 * two registrations. */
static int run_chain(const nricp_method *m, const tcb_sequence *seq, nricp_chain *c, const float *x0,
                     chain_watch *w, tcb_error *err)
{
    int nv = m->n_verts, i = c->source, t = 0, rc = TCB_OK;
    size_t frame = (size_t)nv * 3;
    float *x = malloc(frame * sizeof *x), *next = malloc(frame * sizeof *next);
    if (!x || !next) rc = tcb_fail(err, TCB_ERR_NOMEM, "nricp: out of memory");
    else memcpy(x, x0, frame * sizeof *x);
    for (int k = i; !rc && t < c->n_targets; k += c->step) {
        if (stop_requested(w)) {
            rc = TCB_ERR_INTERRUPTED;
            break;
        }
        int to = k + c->step;
        rc = nricp_register(x, nricp_normals_of(m, i), nv, tcb_seq_frame(seq, to), nricp_normals_of(m, to), nv,
                            &m->params, next, err);
        if (rc) {
            tcb_error_prefix(err, "deforming frame %d onto frame %d: ", k, to);
            break;
        }
        float *swap = x;
        x = next, next = swap;
        if (to == c->targets[t]) memcpy(c->outs + frame * t++, x, frame * sizeof *x);
        count_step(w);
    }
    free(x), free(next);
    return rc;
}

static int chain_length(const nricp_chain *c)
{
    return c->n_targets ? abs(c->targets[c->n_targets - 1] - c->source) : 0;
}

/* ---- chains from pairs ---------------------------------------------------- */

typedef struct hop {
    int source, step, target;
} hop;

/* By source, direction, then distance: a chain's targets nearest first. */
static int hop_order(const void *pa, const void *pb)
{
    const hop *a = pa, *b = pb;
    if (a->source != b->source) return a->source < b->source ? -1 : 1;
    if (a->step != b->step) return a->step < b->step ? -1 : 1;
    int da = abs(a->target - a->source), db = abs(b->target - b->source);
    return (da > db) - (da < db);
}

void nricp_chains_free(nricp_chains *cs)
{
    for (int k = 0; k < cs->n; k++) free(cs->c[k].targets), free(cs->c[k].outs);
    free(cs->c);
    cs->c = NULL, cs->n = 0;
}

/* One chain per (source, direction) of the pairs, each target once; pairs
 * with i = j need none. */
static int build_chains(const nricp_method *m, const int *pairs, int n, nricp_chains *out, tcb_error *err)
{
    hop *h = malloc((size_t)(n > 0 ? n : 1) * sizeof *h);
    out->c = calloc((size_t)(n > 0 ? n : 1), sizeof *out->c);
    out->n = 0;
    int n_hops = 0, rc = TCB_OK;
    if (!h || !out->c) rc = tcb_fail(err, TCB_ERR_NOMEM, "nricp: out of memory for %d pairs", n);
    for (int p = 0; !rc && p < n; p++)
        if (pairs[2 * p] != pairs[2 * p + 1])
            h[n_hops++] = (hop){pairs[2 * p], pairs[2 * p + 1] > pairs[2 * p] ? 1 : -1, pairs[2 * p + 1]};
    if (!rc) qsort(h, (size_t)n_hops, sizeof *h, hop_order);
    size_t frame = (size_t)m->n_verts * 3;
    for (int a = 0, b; !rc && a < n_hops; a = b) {
        for (b = a; b < n_hops && h[b].source == h[a].source && h[b].step == h[a].step; b++) {}
        nricp_chain *c = &out->c[out->n++];
        *c = (nricp_chain){h[a].source, h[a].step, 0, malloc((size_t)(b - a) * sizeof(int)), NULL};
        if (!c->targets) rc = tcb_fail(err, TCB_ERR_NOMEM, "nricp: out of memory");
        for (int t = a; !rc && t < b; t++)
            if (t == a || h[t].target != h[t - 1].target) c->targets[c->n_targets++] = h[t].target;
        if (!rc && !(c->outs = malloc((size_t)c->n_targets * frame * sizeof *c->outs)))
            rc = tcb_fail(err, TCB_ERR_NOMEM, "nricp: out of memory for the deformed clouds");
    }
    free(h);
    if (rc) nricp_chains_free(out);
    return rc;
}

/* ---- the batch ------------------------------------------------------------ */

/* The chains' indices, longest first (the schedule's balance only: every
 * chain's result is the same in any order). */
static int *longest_first(const nricp_chains *cs)
{
    int *order = malloc((size_t)(cs->n > 0 ? cs->n : 1) * sizeof *order);
    if (!order) return NULL;
    for (int k = 0; k < cs->n; k++) order[k] = k;
    for (int a = 1; a < cs->n; a++) /* insertion sort: at most 2F chains */
        for (int b = a; b > 0 && chain_length(&cs->c[order[b]]) > chain_length(&cs->c[order[b - 1]]); b--) {
            int t = order[b];
            order[b] = order[b - 1], order[b - 1] = t;
        }
    return order;
}

/* Marks done the chains whose saved file covers them; returns how many. */
static int resume_chains(const nricp_method *m, nricp_chains *cs, unsigned char *done, const tcb_fit_ctx *ctx)
{
    int resumed = 0;
    for (int k = 0; ctx->work_dir && k < cs->n; k++) {
        char path[TCB_PATH_MAX];
        tcb_error e = {0};
        if (nricp_chain_path(ctx->work_dir, &cs->c[k], path, sizeof path, &e) || !tcb_is_file(path)) continue;
        if (nricp_chain_read(m, &cs->c[k], path, &e) == TCB_OK) done[k] = 1, resumed++;
        else tcb_report_log(&ctx->reporter, TCB_LOG_WARN, "nricp: %s not reused (%s); deforming again", path, e.msg);
    }
    return resumed;
}

/* A chain that cannot be saved (a full disk) costs only the resumption.
 * Called in the critical section that reports progress: the reporter is
 * not thread-safe. */
static void save_chain(const nricp_method *m, const nricp_chain *c, const tcb_fit_ctx *ctx)
{
    char path[TCB_PATH_MAX];
    tcb_error e = {0};
    if (!ctx->work_dir) return;
    if (nricp_chain_path(ctx->work_dir, c, path, sizeof path, &e) || nricp_chain_write(m, c, path, &e))
        tcb_report_log(&ctx->reporter, TCB_LOG_WARN, "nricp: deform chain not saved: %s", e.msg);
}

static int run_chains(const nricp_method *m, const tcb_sequence *seq, nricp_chains *cs, unsigned char *done,
                      const tcb_fit_ctx *ctx, tcb_error *err)
{
    int *order = longest_first(cs), threads = ctx->n_threads > 0 ? ctx->n_threads : 1, n_done = 0;
    tcb_error *errs = calloc((size_t)(cs->n > 0 ? cs->n : 1), sizeof *errs);
    if (!order || !errs) {
        free(order), free(errs);
        return tcb_fail(err, TCB_ERR_NOMEM, "nricp: out of memory for %d chains", cs->n);
    }
    chain_watch w = {ctx, 0, 0};
    for (int k = 0; k < cs->n; k++) w.total += done[k] ? 0 : chain_length(&cs->c[k]);
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (int r = 0; r < cs->n; r++) {
        int k = order[r];
        nricp_chain *c = &cs->c[k];
        if (done[k] || run_chain(m, seq, c, tcb_seq_frame(seq, c->source), &w, &errs[k])) continue;
        done[k] = 1;
#pragma omp critical(nricp_deform_progress)
        save_chain(m, c, ctx);
    }
    int rc = TCB_OK;
    for (int k = 0; k < cs->n; k++) {
        n_done += done[k];
        if (!rc && errs[k].code && errs[k].code != TCB_ERR_INTERRUPTED)
            rc = tcb_fail(err, errs[k].code, "%s", errs[k].msg);
    }
    if (!rc && n_done < cs->n && ctx->work_dir)
        rc = tcb_fail(err, TCB_ERR_INTERRUPTED, "nricp: stopped after %d of %d deform chains (each finished one is saved in %s)",
                      n_done, cs->n, ctx->work_dir);
    else if (!rc && n_done < cs->n)
        rc = tcb_fail(err, TCB_ERR_INTERRUPTED, "nricp: stopped after %d of %d deform chains (no work directory: nothing saved)",
                      n_done, cs->n);
    free(order), free(errs);
    return rc;
}

int nricp_deform_pairs(nricp_method *m, const tcb_sequence *seq, const int *pairs, int n,
                       const tcb_fit_ctx *ctx, tcb_error *err)
{
    nricp_chains_free(&m->chains);
    nricp_chains cs;
    int rc = build_chains(m, pairs, n, &cs, err);
    if (rc) return rc;
    unsigned char *done = calloc((size_t)(cs.n > 0 ? cs.n : 1), 1);
    if (!done) rc = tcb_fail(err, TCB_ERR_NOMEM, "nricp: out of memory");
    int resumed = rc ? 0 : resume_chains(m, &cs, done, ctx);
    if (resumed)
        tcb_report_log(&ctx->reporter, TCB_LOG_INFO, "nricp: %d of %d deform chains resumed from %s", resumed,
                       cs.n, ctx->work_dir);
    if (!rc) rc = run_chains(m, seq, &cs, done, ctx, err);
    free(done);
    if (rc) nricp_chains_free(&cs);
    else m->chains = cs;
    return rc;
}

/* ---- transfer --------------------------------------------------------------- */

/* X of pair (i, j) from the announced chains, NULL when not announced. */
static const float *announced(const nricp_method *m, int i, int j)
{
    for (int k = 0; k < m->chains.n; k++) {
        const nricp_chain *c = &m->chains.c[k];
        if (c->source != i || (j > i) != (c->step > 0)) continue;
        for (int t = 0; t < c->n_targets; t++)
            if (c->targets[t] == j) return c->outs + (size_t)t * m->n_verts * 3;
    }
    return NULL;
}

int nricp_deform_transfer(const nricp_method *m, const tcb_sequence *seq, int i, int j, const float *src,
                          float *out, tcb_error *err)
{
    size_t bytes = (size_t)m->n_verts * 3 * sizeof *out;
    /* The announced chains start at P_i; other points get a chain of their own. */
    const float *x = memcmp(src, tcb_seq_frame(seq, i), bytes) == 0 ? announced(m, i, j) : NULL;
    if (i == j || x) {
        memcpy(out, i == j ? src : x, bytes);
        return TCB_OK;
    }
    nricp_chain c = {i, j > i ? 1 : -1, 1, &j, out};
    return run_chain(m, seq, &c, src, NULL, err);
}

/* ---- cost ------------------------------------------------------------------- */

/* A chain from frame i goes forward at least d frames when one of the P
 * pairs does: 1 − (1 − (F − i − d) / (F (F − 1)))^P. Its expected length
 * is the sum over d, and backward mirrors forward. Crane (F = 175,
 * P = 500): 16 317, its split's chains 16 817. */
double nricp_deform_expected_steps(int n_frames, int n_pairs)
{
    double s = 0, per_pair = (double)n_frames * (n_frames - 1);
    for (int i = 0; i < n_frames; i++)
        for (int d = 1; d < n_frames - i; d++) s += 1 - pow(1 - (n_frames - i - d) / per_pair, n_pairs);
    return 2 * s;
}
