/* Cost of the atlas losses per training step at the paper's sizes (B = 4
 * shapes, M = N = 2500 points, P = 10 patches), value and gradient, and of
 * the evaluation's regular UV sets (made once per run and size m).
 *
 * The Chamfer loss is B·(M + N) exact nearest-neighbour queries; its points
 * are area-uniform on a unit sphere, the predictions a noisy copy of other
 * samples, like a fitted atlas. Best of `reps` runs.
 *
 * usage: bench_atlas_loss [reps]      (threads: OMP_NUM_THREADS) */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>

#include "bench_util.h"
#include "methods/atlas/loss_chamfer.h"
#include "methods/atlas/loss_dsr.h"
#include "methods/atlas/loss_metric.h"
#include "methods/atlas/uv_regular.h"

enum { B = 4, M = 2500, N = 2500, P = 10 };

static void die(const tcb_error *err)
{
    fprintf(stderr, "bench_atlas_loss: %s\n", err->msg);
    exit(1);
}

/* n points on the unit sphere plus Gaussian noise of size sigma. */
static void sphere(tcb_rng *rng, float *p, int n, double sigma)
{
    for (int i = 0; i < n; i++) {
        double v[3], len = 0.0;
        for (int c = 0; c < 3; c++) v[c] = tcb_rng_normal(rng), len += v[c] * v[c];
        for (int c = 0; c < 3; c++)
            p[3 * i + c] = (float)(v[c] / sqrt(len) + sigma * tcb_rng_normal(rng));
    }
}

int main(int argc, char **argv)
{
    int reps = argc > 1 ? bench_positive_int(argv[1], "reps", "top of bench/atlas_loss.c") : 10;
    size_t np = (size_t)B * M * 3;
    float *pred = malloc(np * sizeof *pred), *target = malloc((size_t)B * N * 3 * sizeof *target);
    float *pu = malloc(np * sizeof *pu), *pv = malloc(np * sizeof *pv);
    float *g0 = calloc(np, sizeof *g0), *g1 = calloc(np, sizeof *g1);
    float *uv = malloc(3125 * 2 * sizeof *uv);
    if (!pred || !target || !pu || !pv || !g0 || !g1 || !uv) return 1;
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 1, "bench/atlas_loss");
    sphere(&rng, pred, B * M, 0.01);
    sphere(&rng, target, B * N, 0.0);
    for (size_t i = 0; i < np; i++) {
        pu[i] = (float)(0.3 * tcb_rng_normal(&rng) + (i % 3 == 0));
        pv[i] = (float)(0.3 * tcb_rng_normal(&rng) + (i % 3 == 1));
    }
    double area_gt[B] = {4 * M_PI, 4 * M_PI, 4 * M_PI, 4 * M_PI};
    tcb_atlas_dsr_weights w = tcb_atlas_dsr_defaults();

    double best[3] = {1e300, 1e300, 1e300}, loss;
    tcb_error err = {0};
    for (int r = 0; r < reps; r++) {
        double t0 = bench_now_ms();
        if (tcb_atlas_chamfer_loss(pred, target, B, M, N, 1.0f, &loss, g0, &err)) die(&err);
        double t1 = bench_now_ms();
        if (tcb_atlas_metric_loss(pu, pv, B, M, 0.1f, &loss, g0, g1, &err)) die(&err);
        double t2 = bench_now_ms();
        if (tcb_atlas_dsr_loss(pu, pv, B, M, P, area_gt, &w, 1e-3f, &loss, NULL, g0, g1, &err))
            die(&err);
        double t3 = bench_now_ms();
        best[0] = fmin(best[0], t1 - t0);
        best[1] = fmin(best[1], t2 - t1);
        best[2] = fmin(best[2], t3 - t2);
    }
    printf("atlas losses, value + gradient, B=%d M=%d N=%d P=%d, best of %d, %d thread(s)\n", B,
           M, N, P, reps, omp_get_max_threads());
    printf("  chamfer  %8.2f ms\n  metric   %8.2f ms\n  dsr      %8.2f ms\n", best[0], best[1],
           best[2]);

    printf("regular UV set (once per run and m), one run each\n");
    static const int sizes[] = {312, 347, 1041, 3125}; /* P' = 10, 9, 3, 1 */
    for (size_t s = 0; s < sizeof sizes / sizeof *sizes; s++) {
        double t0 = bench_now_ms();
        if (tcb_atlas_uv_regular(sizes[s], &rng, uv, &err)) die(&err);
        printf("  m=%-5d %8.1f ms\n", sizes[s], bench_now_ms() - t0);
    }
    free(pred), free(target), free(pu), free(pv), free(g0), free(g1), free(uv);
    return 0;
}
