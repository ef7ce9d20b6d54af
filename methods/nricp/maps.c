/* Consecutive vertex maps for propagate_simple / propagate_bijective
 * (reference-protocol §6.3): c_k takes frame k's vertices to frame k+1's by
 * registering P_k onto P_{k+1} and then matching the deformed P_k to
 * P_{k+1}, by nearest neighbour (simple) or by an exact linear assignment on
 * squared distances (bijective). The reverse maps (k+1 → k, registering
 * P_{k+1} onto P_k) are computed as well, so pairs with j < i run the chain
 * backwards. A chain never leaves its block (DFAUST: its subject; pairs are
 * drawn inside blocks and nricp_transfer refuses others), so the maps
 * between the last frame of a block and the first of the next are not
 * registered: they stay the identity, which keeps the layout and the
 * checkpoint's checks (a permutation) as they are. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "methods/nricp/nricp_internal.h"
#include "tcb/fsutil.h"
#include "tcb/lap.h"
#include "tcb/nn.h"

/* cost[r][c] = ||moved_r − target_c||², [n][n], in double as scipy would. */
static double *sq_dist_matrix(const float *moved, const float *target, int n)
{
    double *cost = malloc((size_t)n * n * sizeof *cost);
    if (!cost) return NULL;
    for (int r = 0; r < n; r++) {
        const float *a = moved + 3 * (size_t)r;
        double *row = cost + (size_t)r * n;
        for (int c = 0; c < n; c++) {
            const float *b = target + 3 * (size_t)c;
            double dx = (double)a[0] - b[0], dy = (double)a[1] - b[1], dz = (double)a[2] - b[2];
            row[c] = dx * dx + dy * dy + dz * dz;
        }
    }
    return cost;
}

int nricp_assign(const float *moved, const float *target, int n, int32_t *map, tcb_error *err)
{
    double *cost = sq_dist_matrix(moved, target, n);
    int rc = cost ? tcb_lap_solve(cost, n, n, map, NULL, err)
                  : tcb_fail(err, TCB_ERR_NOMEM, "nricp: out of memory for a %d x %d cost matrix", n, n);
    free(cost);
    return rc;
}

/* map = c_{a→b}: register frame a onto frame b, then match; the identity
 * across a block boundary (no chain uses it). */
static int one_map(const nricp_method *m, const tcb_sequence *seq, int a, int b, int32_t *map,
                   tcb_error *err)
{
    int nv = m->n_verts, lo, hi;
    tcb_seq_block_of(seq, a, &lo, &hi);
    if (b < lo || b >= hi) {
        for (int v = 0; v < nv; v++) map[v] = v;
        return TCB_OK;
    }
    const float *pa = tcb_seq_frame(seq, a), *pb = tcb_seq_frame(seq, b);
    const float *na = nricp_normals_of(m, a), *nb = nricp_normals_of(m, b);
    float *moved = malloc((size_t)nv * 3 * sizeof *moved);
    if (!moved) return tcb_fail(err, TCB_ERR_NOMEM, "nricp: out of memory");
    int rc = nricp_register(pa, na, nv, pb, nb, nv, &m->params, moved, err);
    if (!rc && m->strategy == NRICP_SIMPLE) rc = tcb_nn_nearest(pb, nv, moved, nv, map, NULL, err);
    if (!rc && m->strategy == NRICP_BIJECTIVE) rc = nricp_assign(moved, pb, nv, map, err);
    free(moved);
    if (rc) tcb_error_prefix(err, "map frame %d -> %d: ", a, b);
    return rc;
}

/* The state of an unfinished fit in the cell's work directory. */
#define PARTIAL_NAME "nricp_maps.partial"
/* Seconds between two saves of an unfinished fit (besides the one a stop
 * request makes): a registration of crane takes 1-16 s, its state 14 MB. */
#define SAVE_EVERY_S 60.0

typedef struct fit_state {
    unsigned char *done;  /* [jobs] 1 once that row of the maps is computed */
    int n_done, jobs;
    double earlier_s;     /* what the processes before this one spent */
    double start_s, saved_s;
    char path[TCB_PATH_MAX]; /* "" without a work directory */
} fit_state;

/* Job t's map: t = 2k registers frame k onto k+1, t = 2k+1 frame k+1 onto k. */
static void job_frames(int t, int *a, int *b)
{
    int k = t / 2;
    *a = t % 2 ? k + 1 : k, *b = t % 2 ? k : k + 1;
}

static int save_state(const nricp_method *m, fit_state *st, tcb_error *err)
{
    st->saved_s = tcb_now_seconds();
    return nricp_write_state(m, st->done, st->earlier_s + st->saved_s - st->start_s, st->path, err);
}

/* Continues an unfinished fit from the work directory when it has one
 * written for this method and sequence; warns and starts afresh otherwise. */
static void resume(nricp_method *m, const tcb_fit_ctx *ctx, fit_state *st)
{
    if (!st->path[0] || !tcb_is_file(st->path)) return;
    tcb_error e = {0};
    if (nricp_read_state(m, st->done, &st->earlier_s, st->path, &e)) {
        memset(st->done, 0, (size_t)st->jobs);
        st->earlier_s = 0;
        tcb_report_log(&ctx->reporter, TCB_LOG_WARN, "nricp: not resumed (%s); registering every map again",
                       e.msg);
        return;
    }
    for (int t = 0; t < st->jobs; t++) st->n_done += st->done[t];
    tcb_report_log(&ctx->reporter, TCB_LOG_INFO, "nricp: resuming the consecutive maps with %d of %d done from %s (%.0f s in)",
                   st->n_done, st->jobs, st->path, st->earlier_s);
}

/* Marks a row of the maps done; saves the state when the last save is a
 * minute old. Called inside the critical section of the fit's loop. A
 * state that cannot be written (a full disk) costs only the resumption:
 * the fit goes on, rather than fail a cell that would stay failed once the
 * disk has room again. */
static void finish_map(const nricp_method *m, const tcb_fit_ctx *ctx, fit_state *st, size_t row)
{
    st->done[row] = 1;
    tcb_report_progress(&ctx->reporter, ++st->n_done, st->jobs, "nricp: consecutive maps");
    tcb_error se = {0};
    if (st->path[0] && st->n_done < st->jobs && tcb_now_seconds() - st->saved_s >= SAVE_EVERY_S &&
        save_state(m, st, &se))
        tcb_report_log(&ctx->reporter, TCB_LOG_WARN, "nricp: maps not saved: %s", se.msg);
}

static int compute_maps(nricp_method *m, const tcb_sequence *seq, const tcb_fit_ctx *ctx, fit_state *st,
                        tcb_error *errs)
{
    int threads = ctx->n_threads > 0 ? ctx->n_threads : 1;
    /* Each registration is deterministic and writes only its own row, so
     * the maps depend neither on the thread count, nor on the schedule, nor
     * on where an earlier process stopped. A stop request lets the maps in
     * progress finish and starts no other. */
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (int t = 0; t < st->jobs; t++) {
        int a, b;
        job_frames(t, &a, &b);
        size_t row = nricp_map_row(m, a, b);
        if (st->done[row] || tcb_fit_interrupted(ctx)) continue;
        if (one_map(m, seq, a, b, m->maps + nricp_map_at(m, a, b), &errs[t])) continue;
#pragma omp critical(nricp_progress)
        finish_map(m, ctx, st, row);
    }
    for (int t = 0; t < st->jobs; t++)
        if (errs[t].code) return t;
    return -1;
}

int nricp_fit_maps(nricp_method *m, const tcb_sequence *seq, const tcb_fit_ctx *ctx,
                   tcb_error *err)
{
    fit_state st = {.jobs = 2 * (m->n_frames - 1), .start_s = tcb_now_seconds()};
    st.saved_s = st.start_s;
    free(m->maps);
    m->maps = calloc(nricp_maps_len(m), sizeof *m->maps);
    st.done = calloc((size_t)st.jobs, 1);
    tcb_error *errs = calloc((size_t)st.jobs, sizeof *errs);
    int rc = !m->maps || !st.done || !errs ? tcb_fail(err, TCB_ERR_NOMEM, "nricp: out of memory for %d maps", st.jobs)
                                           : TCB_OK;
    if (!rc && ctx->work_dir) rc = tcb_path_join(st.path, sizeof st.path, err, "%s/%s", ctx->work_dir, PARTIAL_NAME);
    if (!rc) resume(m, ctx, &st);
    int failed = rc ? -1 : compute_maps(m, seq, ctx, &st, errs);
    if (!rc && failed >= 0) rc = tcb_fail(err, errs[failed].code, "%s", errs[failed].msg);
    if (!rc && st.n_done < st.jobs) {
        const char *said = st.path[0] ? "; maps saved in " : " (no work directory: nothing saved)", *where = st.path;
        tcb_error se = {0};
        /* Stopped either way: the cell resumes, whether or not the maps were kept. */
        if (st.path[0] && save_state(m, &st, &se)) {
            tcb_report_log(&ctx->reporter, TCB_LOG_WARN, "nricp: maps not saved: %s", se.msg);
            said = " (the maps could not be saved)", where = "";
        }
        rc = tcb_fail(err, TCB_ERR_INTERRUPTED, "nricp: stopped after %d of %d consecutive maps%s%s", st.n_done,
                      st.jobs, said, where);
    }
    if (!rc && ctx->resumed_fit_s) *ctx->resumed_fit_s = st.earlier_s;
    if (!rc && st.path[0]) remove(st.path);
    free(st.done);
    free(errs);
    return rc;
}

/* idx[v] = the vertex of frame j reached from vertex v of frame i through
 * the consecutive maps. TCSR composes only `range(i, j)`, so for j < i its
 * chain silently did nothing (identity indices); here j < i follows the
 * reverse maps i → i−1 → … → j. */
void nricp_compose(const nricp_method *m, int i, int j, int32_t *idx)
{
    int step = j > i ? 1 : -1;
    for (int v = 0; v < m->n_verts; v++) idx[v] = v;
    for (int k = i; k != j; k += step) {
        const int32_t *c = m->maps + nricp_map_at(m, k, k + step);
        for (int v = 0; v < m->n_verts; v++) idx[v] = c[idx[v]];
    }
}
