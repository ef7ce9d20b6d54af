/* Normal-compatible 1-NN and 8-NN (nricp's queries, methods/nricp/knn_compat.h):
 * the kd-tree that bounds its nodes' normals beside its peer, FLANN's exact
 * kd-tree asked for a block of plain nearest candidates that is filtered and
 * widened 4x until k compatible ones are in it (what nricp did before; for
 * k = 1 the first pass is the plain nearest neighbour).
 *
 * Workloads: n points on a sphere shell with outward normals, n queries near
 * it whose normals face outwards ("near": the nearest point is nearly always
 * compatible, as between close frames) or inwards ("far side": every
 * compatible point lies on the other hemisphere, as for a thin part seen
 * from its back between frames far apart). Both answers are compared; each
 * time includes building the index. Best of `reps` runs, one thread.
 *
 * usage: bench_knn_compat [reps] */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_util.h"
#include "methods/nricp/knn_compat.h"
#include "tcb/nn.h"
#include "tcb/rng.h"

#define PROG "bench_knn_compat"

static void shell(tcb_rng *r, float *p, float *nrm, int n, float flip)
{
    for (int i = 0; i < n; i++) {
        double v[3], len = 0;
        for (int c = 0; c < 3; c++) v[c] = tcb_rng_normal(r), len += v[c] * v[c];
        double radius = 1 + 0.05 * tcb_rng_uniform(r);
        for (int c = 0; c < 3; c++) {
            nrm[3 * i + c] = flip * (float)(v[c] / sqrt(len));
            p[3 * i + c] = (float)(radius * v[c] / sqrt(len));
        }
    }
}

static int compatible(const float *a, const float *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2] >= 0.0f; }

/* The peer: plain k-NN blocks from FLANN for all pending queries at once
 * (at most 2^22 candidates in flight), filtered, widened until settled. */
static void peer(const float *pts, const float *nrm, int n, const float *q, const float *qn, int nq, int k,
                 int32_t *idx)
{
    tcb_nn *nn;
    tcb_error err;
    if (tcb_nn_build_backend(pts, n, TCB_NN_KDTREE, &nn, &err)) bench_die(PROG, "%s", err.msg);
    int32_t *pend = malloc((size_t)nq * sizeof *pend), *ridx = malloc((size_t)(1 << 22) * sizeof *ridx);
    float *rd2 = malloc((size_t)(1 << 22) * sizeof *rd2), *buf = malloc((size_t)nq * 12);
    int np = nq;
    for (int t = 0; t < nq; t++) pend[t] = t;
    for (int block = 8 < n ? 8 : n; np > 0; block = block * 4 < n ? block * 4 : n) {
        int kept = 0, chunk = (1 << 22) / block;
        for (int start = 0; start < np; start += chunk) {
            int m = np - start < chunk ? np - start : chunk;
            for (int a = 0; a < m; a++) memcpy(buf + 3 * a, q + 3 * (size_t)pend[start + a], 12);
            /* k = 1 starts with the plain nearest neighbour, as nricp did */
            int width = k == 1 && block == 8 ? 1 : block;
            if (tcb_nn_queryk(nn, buf, m, width, ridx, rd2, &err)) bench_die(PROG, "%s", err.msg);
            for (int a = 0; a < m; a++) {
                int t = pend[start + a], found = 0;
                const int32_t *row = ridx + (size_t)a * width;
                for (int b = 0; b < width && found < k; b++)
                    if (compatible(qn + 3 * (size_t)t, nrm + 3 * (size_t)row[b])) idx[(size_t)t * k + found++] = row[b];
                if (found < k && block < n) pend[kept++] = t;
                else
                    for (int b = found; b < k; b++) idx[(size_t)t * k + b] = -1;
            }
        }
        np = kept;
    }
    tcb_nn_free(nn);
    free(pend), free(ridx), free(rd2), free(buf);
}

static void tree(const float *pts, const float *nrm, int n, const float *q, const float *qn, int nq, int k,
                 int32_t *idx, int *cnt)
{
    nricp_compat_index *ix;
    tcb_error err;
    if (nricp_compat_build(pts, nrm, n, &ix, &err) || nricp_knn_compat(ix, q, qn, nq, k, idx, NULL, cnt, &err))
        bench_die(PROG, "%s", err.msg);
    nricp_compat_free(ix);
}

int main(int argc, char **argv)
{
    int reps = argc > 1 ? bench_positive_int(argv[1], "reps", "top of bench/" PROG ".c") : 3;
    printf("normal-compatible k-NN, n points and n queries, one thread, ms (best of %d)\n", reps);
    printf("%-9s %6s %2s %12s %12s %7s\n", "queries", "n", "k", "FLANN+filter", "normal tree", "ratio");
    for (int far = 0; far <= 1; far++)
        for (int n = 2500; n <= 10000; n *= 4)
            for (int k = 1; k <= 8; k += 7) {
                float *p = malloc((size_t)n * 12), *nrm = malloc((size_t)n * 12), *q = malloc((size_t)n * 12),
                      *qn = malloc((size_t)n * 12);
                int32_t *a = malloc((size_t)n * k * sizeof *a), *b = malloc((size_t)n * k * sizeof *b);
                int *cnt = malloc((size_t)n * sizeof *cnt);
                tcb_rng r;
                tcb_rng_seed_stream(&r, 1, PROG);
                shell(&r, p, nrm, n, 1);
                shell(&r, q, qn, n, far ? -1 : 1);
                double best[2] = {1e300, 1e300};
                for (int rep = 0; rep < reps; rep++) {
                    double t0 = bench_now_ms();
                    peer(p, nrm, n, q, qn, n, k, a);
                    double t1 = bench_now_ms();
                    tree(p, nrm, n, q, qn, n, k, b, cnt);
                    double t2 = bench_now_ms();
                    best[0] = t1 - t0 < best[0] ? t1 - t0 : best[0];
                    best[1] = t2 - t1 < best[1] ? t2 - t1 : best[1];
                }
                /* exact both: the same points (ties aside, which random reals do not make) */
                if (memcmp(a, b, (size_t)n * k * sizeof *a)) bench_die(PROG, "the two answers differ");
                printf("%-9s %6d %2d %12.1f %12.1f %6.2fx\n", far ? "far side" : "near", n, k, best[0], best[1],
                       best[0] / best[1]);
                free(p), free(nrm), free(q), free(qn), free(a), free(b), free(cnt);
            }
    return 0;
}
