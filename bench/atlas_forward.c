/* One forward + backward of the atlas network (methods/atlas/model.h): ms
 * and GFLOP/s at the paper's scale and at a smaller CPU scale, with the
 * tangents (MCA, DSR: the loss needs φ_u, φ_v) and without (AtlasNet: CD
 * only, a third of the decoder work).
 *
 * FLOPs are the minimal count of atlas_bench.h (2 per multiply-add of the
 * layers' products; elementwise work not counted). Best of `reps` runs.
 *
 * Measured on the 2-core AMD EPYC dev machine (quiet, 2 threads, best of 5;
 * fp32 peak ≈ 230 GFLOP/s, OpenBLAS sgemm 190–200 on these shapes):
 *     scale  tangents      fwd ms  bwd ms  step ms  GFLOP/s
 *     cpu    yes             13.7    17.2     30.9   136
 *     cpu    no              10.0     9.3     19.2   114
 *     paper  yes            234     419      652     187
 *     paper  no             100     149      248     173
 * One thread, cpu scale: 55 ms with tangents, 33 ms without.
 *
 * usage: bench_atlas_forward [reps [cpu|paper]]   (threads: OMP_NUM_THREADS) */
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "atlas_bench.h"
#include "methods/atlas/model.h"

typedef struct {
    const char *name;
    int C, P, M, B, N;
} scale;

static void fill(float *x, size_t n, double lo, double hi, tcb_rng *r)
{
    for (size_t i = 0; i < n; i++) x[i] = (float)(lo + (hi - lo) * tcb_rng_uniform(r));
}

static int run(const scale *s, int reps)
{
    tcb_error err = {0};
    tcb_atlas_model *m;
    tcb_atlas_work *w;
    if (tcb_atlas_model_create(s->C, s->P, &m, &err) ||
        tcb_atlas_work_create(m, s->B, s->N, s->M, &w, &err)) {
        fprintf(stderr, "bench_atlas_forward: %s\n", err.msg);
        return 1;
    }
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 1, "bench/atlas");
    tcb_atlas_model_init(m, &rng);
    size_t nin = (size_t)s->B * s->N * 3, nout = (size_t)s->B * s->M * 3;
    float *clouds = malloc(nin * sizeof(float)), *uv = malloc((size_t)s->M * 2 * sizeof(float));
    float *out = malloc(6 * nout * sizeof(float));
    if (!clouds || !uv || !out) return 1;
    fill(clouds, nin, -0.5, 0.5, &rng);
    fill(uv, (size_t)s->M * 2, 0, 1, &rng);
    fill(out + 3 * nout, 3 * nout, -1, 1, &rng); /* upstream gradients */
    for (int nt = 2; nt >= 0; nt -= 2) {
        double best_f = 1e300, best_b = 1e300, fm, bm;
        for (int r = 0; r < reps; r++) {
            double t0 = bench_now_ms();
            tcb_atlas_model_forward(m, w, clouds, uv, out, nt ? out + nout : NULL,
                                    nt ? out + 2 * nout : NULL);
            double t1 = bench_now_ms();
            tcb_atlas_model_zero_grad(m);
            if (tcb_atlas_model_backward(m, w, out + 3 * nout, nt ? out + 4 * nout : NULL,
                                         nt ? out + 5 * nout : NULL, &err)) {
                fprintf(stderr, "bench_atlas_forward: %s\n", err.msg);
                return 1;
            }
            double t2 = bench_now_ms();
            if (t1 - t0 < best_f) best_f = t1 - t0;
            if (t2 - t1 < best_b) best_b = t2 - t1;
        }
        bench_atlas_macs(s->C, s->P, s->M, s->B, s->N, nt, &fm, &bm);
        printf("%-6s C=%-4d P=%-2d M=%-4d B=%d N=%-4d %-11s fwd %8.1f ms %6.1f GF/s | "
               "bwd %8.1f ms %6.1f GF/s | step %8.1f ms %6.1f GF/s (%.1f GFLOP)\n",
               s->name, s->C, s->P, s->M, s->B, s->N, nt ? "tangents" : "no tangents", best_f,
               2 * fm / best_f * 1e-6, best_b, 2 * bm / best_b * 1e-6, best_f + best_b,
               2 * (fm + bm) / (best_f + best_b) * 1e-6, 2 * (fm + bm) * 1e-9);
    }
    free(clouds), free(uv), free(out);
    tcb_atlas_work_free(w);
    tcb_atlas_model_free(m);
    return 0;
}

int main(int argc, char **argv)
{
    int reps = argc > 1 ? bench_positive_int(argv[1], "reps", "top of bench/atlas_forward.c") : 3;
    static const scale scales[] = {
        {"cpu", 256, 10, 1000, 4, 2500},
        {"paper", 1024, 10, 2500, 4, 2500},
    };
    printf("atlas network forward + backward, best of %d, %d thread(s)\n", reps,
           omp_get_max_threads());
    int matched = 0;
    for (size_t i = 0; i < sizeof scales / sizeof *scales; i++) {
        if (argc >= 3 && strcmp(argv[2], scales[i].name) != 0) continue;
        matched++;
        if (run(&scales[i], reps)) return 1;
    }
    if (!matched) fprintf(stderr, "bench_atlas_forward: no scale named '%s' (cpu, paper)\n", argv[2]);
    return matched ? 0 : 2;
}
