/* Cost of one pair's correspondence metrics (tcb_pair_metrics_compute): the
 * O(K²) rank dominates. K = 1297 is the cat (ANIM), 6890 DFAUST, 10002 the
 * AMA crane. Two predictions: every vertex wrong (the worst case, a full K²
 * scan), and a third of the vertices exact (exact ones skip the scan).
 * Best of `reps` runs.
 *
 * usage: bench_metrics [reps]      (threads: OMP_NUM_THREADS) */
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>

#include "bench_util.h"
#include "tcb/metrics.h"
#include "tcb/rng.h"

static double time_pair(const float *v, int K, const int32_t *pred, int reps)
{
    double best = 1e300;
    for (int r = 0; r < reps; r++) {
        tcb_pair_metrics m;
        tcb_error err = {0};
        double t0 = bench_now_ms();
        if (tcb_pair_metrics_compute(v, K, pred, &m, &err)) {
            fprintf(stderr, "bench_metrics: %s\n", err.msg);
            exit(1);
        }
        double t = bench_now_ms() - t0;
        if (t < best) best = t;
    }
    return best;
}

int main(int argc, char **argv)
{
    int reps = argc > 1 ? bench_positive_int(argv[1], "reps", "top of bench/bench_metrics.c") : 5;
    static const int sizes[] = {1297, 6890, 10002};
    printf("one pair's metrics, best of %d, %d thread(s)\n", reps, omp_get_max_threads());
    printf("%8s %16s %16s\n", "K", "all wrong ms", "1/3 exact ms");
    for (size_t s = 0; s < sizeof sizes / sizeof *sizes; s++) {
        int K = sizes[s];
        float *v = malloc((size_t)K * 3 * sizeof(float));
        int32_t *pred = malloc((size_t)K * sizeof(int32_t));
        if (!v || !pred) return 1;
        tcb_rng rng;
        tcb_rng_seed_stream(&rng, 1, "bench/metrics");
        for (int i = 0; i < 3 * K; i++) v[i] = (float)tcb_rng_uniform(&rng);
        for (int k = 0; k < K; k++) pred[k] = (k + 1 + (int)tcb_rng_below(&rng, 50)) % K;
        double wrong = time_pair(v, K, pred, reps);
        for (int k = 0; k < K; k += 3) pred[k] = k;
        double mixed = time_pair(v, K, pred, reps);
        printf("%8d %16.2f %16.2f\n", K, wrong, mixed);
        free(v), free(pred);
    }
    return 0;
}
