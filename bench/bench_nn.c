/* Brute force vs FLANN kd-tree for exact 1-NN in 3-D: the measurement behind
 * TCB_NN_BRUTE_MAX in core/nn.c.
 *
 * Workload as tcbench uses it: n points, n queries (projecting K predicted
 * points onto K GT vertices, Chamfer between similar-sized clouds), points
 * uniform in the unit cube. Each time includes building the index, since
 * every call site builds one per query set. Best of `reps` runs.
 *
 * usage: bench_nn [reps]      (threads: OMP_NUM_THREADS) */
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>

#include "bench_util.h"
#include "tcb/nn.h"
#include "tcb/rng.h"

static double time_backend(tcb_nn_backend backend, const float *pts, const float *queries,
                           int n, int reps, int32_t *idx, float *d2)
{
    double best = 1e300;
    for (int r = 0; r < reps; r++) {
        tcb_error err = {0};
        tcb_nn *nn;
        double t0 = bench_now_ms();
        if (tcb_nn_build_backend(pts, n, backend, &nn, &err) ||
            tcb_nn_query1(nn, queries, n, idx, d2, &err)) {
            fprintf(stderr, "bench_nn: %s\n", err.msg);
            exit(1);
        }
        double t = bench_now_ms() - t0;
        tcb_nn_free(nn);
        if (t < best) best = t;
    }
    return best;
}

int main(int argc, char **argv)
{
    int reps = argc > 1 ? bench_positive_int(argv[1], "reps", "top of bench/bench_nn.c") : 5;
    static const int sizes[] = {1000, 2500, 5000, 10000, 20000};
    int nmax = sizes[sizeof sizes / sizeof *sizes - 1];
    float *pts = malloc((size_t)nmax * 3 * sizeof(float));
    float *queries = malloc((size_t)nmax * 3 * sizeof(float));
    int32_t *idx = malloc((size_t)nmax * sizeof(int32_t));
    float *d2 = malloc((size_t)nmax * sizeof(float));
    if (!pts || !queries || !idx || !d2) return 1;
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 1, "bench/nn");
    for (int i = 0; i < 3 * nmax; i++) pts[i] = (float)tcb_rng_uniform(&rng);
    for (int i = 0; i < 3 * nmax; i++) queries[i] = (float)tcb_rng_uniform(&rng);

    printf("exact 1-NN, n points x n queries, build included, best of %d, %d thread(s)\n",
           reps, omp_get_max_threads());
    printf("%8s %12s %12s %14s\n", "n", "brute ms", "kd-tree ms", "brute/kd-tree");
    for (size_t s = 0; s < sizeof sizes / sizeof *sizes; s++) {
        int n = sizes[s];
        double tb = time_backend(TCB_NN_BRUTE, pts, queries, n, reps, idx, d2);
        double tk = time_backend(TCB_NN_KDTREE, pts, queries, n, reps, idx, d2);
        printf("%8d %12.3f %12.3f %14.2f\n", n, tb, tk, tb / tk);
    }
    free(pts), free(queries), free(idx), free(d2);
    return 0;
}
