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
#include <stdlib.h>
#include <string.h>

#include "methods/nricp/nricp_internal.h"
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
    const float *na = m->normals + (size_t)a * nv * 3, *nb = m->normals + (size_t)b * nv * 3;
    float *moved = malloc((size_t)nv * 3 * sizeof *moved);
    if (!moved) return tcb_fail(err, TCB_ERR_NOMEM, "nricp: out of memory");
    int rc = nricp_register(pa, na, nv, pb, nb, nv, &m->params, moved, err);
    if (!rc && m->strategy == NRICP_SIMPLE) rc = tcb_nn_nearest(pb, nv, moved, nv, map, NULL, err);
    if (!rc && m->strategy == NRICP_BIJECTIVE) {
        double *cost = sq_dist_matrix(moved, pb, nv);
        rc = cost ? tcb_lap_solve(cost, nv, nv, map, NULL, err)
                  : tcb_fail(err, TCB_ERR_NOMEM, "nricp: out of memory for a %d x %d cost matrix", nv, nv);
        free(cost);
    }
    free(moved);
    if (rc) tcb_error_prefix(err, "map frame %d -> %d: ", a, b);
    return rc;
}

int nricp_fit_maps(nricp_method *m, const tcb_sequence *seq, const tcb_fit_ctx *ctx,
                   tcb_error *err)
{
    int steps = m->n_frames - 1, jobs = 2 * steps;
    free(m->maps);
    m->maps = malloc(nricp_maps_len(m) * sizeof *m->maps);
    tcb_error *errs = calloc((size_t)jobs, sizeof *errs);
    if (!m->maps || !errs) {
        free(errs);
        return tcb_fail(err, TCB_ERR_NOMEM, "nricp: out of memory for %d maps", jobs);
    }
    int threads = ctx->n_threads > 0 ? ctx->n_threads : 1, done = 0;
    /* Each registration is deterministic and writes only its own row, so
     * the maps do not depend on the thread count or the schedule. */
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (int t = 0; t < jobs; t++) {
        int k = t / 2, a = t % 2 ? k + 1 : k, b = t % 2 ? k : k + 1;
        one_map(m, seq, a, b, m->maps + nricp_map_at(m, a, b), &errs[t]);
#pragma omp critical(nricp_progress)
        tcb_report_progress(&ctx->reporter, ++done, jobs, "nricp: consecutive maps");
    }
    int rc = TCB_OK;
    for (int t = 0; t < jobs && !rc; t++)
        if (errs[t].code) rc = tcb_fail(err, errs[t].code, "%s", errs[t].msg);
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
