/* The layers' tall products, cut into one row block per thread
 * (neural/layers.c, sgemm_rows), against the same product in one OpenBLAS
 * call with OpenBLAS's own threads: the measurement behind the split.
 *
 * Shapes (rows x in -> out) of the trained methods' largest layers: cc's
 * encoder, last convolution (16 triplets of 2 500 points, 128 -> 1 024) and
 * a decoder layer (64 -> 64); neupig's hidden layer at `paper` (6 frames of
 * a 10 000-vertex template, 512 -> 512); dynosurf's blend network's hidden
 * layer (10 000 points x 30 control points, 128 -> 128). Forward: y = x·Wᵀ
 * + b (tcb_linear_forward); backward: dW += dyᵀ·x and dx = dy·W
 * (tcb_linear_backward, whose dW stays one OpenBLAS call). The peer makes
 * the same calls on the whole rows, its bias rows filled on the threads as
 * tcb_linear_forward fills them. Best of `reps` runs each; GFLOP/s
 * counts 2·rows·in·out a product. Timings only; nothing is asserted.
 *
 * usage: bench_linear [reps]      (threads: OMP_NUM_THREADS) */
#include <cblas.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_util.h"
#include "neural/layers.h"
#include "tcb/rng.h"

typedef struct shape {
    const char *name;
    int rows, in, out;
} shape;

static const shape shapes[] = {
    {"cc encoder conv3", 40000, 128, 1024},
    {"cc decoder layer", 40000, 64, 64},
    {"neupig hidden (paper)", 60000, 512, 512},
    {"dynosurf blend hidden", 300000, 128, 128},
};

typedef struct tensors {
    float *x, *W, *b, *y, *dy, *dx, *dW;
} tensors;

static void peer_forward(tensors *t, const shape *s)
{
    /* the bias rows filled on the threads, as tcb_linear_forward fills them */
#pragma omp parallel for schedule(static)
    for (int r = 0; r < s->rows; r++) memcpy(t->y + (size_t)r * s->out, t->b, (size_t)s->out * sizeof(float));
    cblas_sgemm(CblasRowMajor, CblasNoTrans, CblasTrans, s->rows, s->out, s->in, 1.0f, t->x, s->in, t->W, s->in,
                1.0f, t->y, s->out);
}

static void peer_backward(tensors *t, const shape *s)
{
    cblas_sgemm(CblasRowMajor, CblasTrans, CblasNoTrans, s->out, s->in, s->rows, 1.0f, t->dy, s->out, t->x, s->in,
                1.0f, t->dW, s->in);
    cblas_sgemm(CblasRowMajor, CblasNoTrans, CblasNoTrans, s->rows, s->in, s->out, 1.0f, t->dy, s->out, t->W,
                s->in, 0.0f, t->dx, s->in);
}

static void split_forward(tensors *t, const shape *s)
{
    tcb_linear_forward(t->y, t->x, t->W, t->b, s->rows, 0, s->in, s->out);
}

static void split_backward(tensors *t, const shape *s)
{
    tcb_linear_backward(t->dx, t->dW, NULL, t->dy, t->x, t->W, s->rows, 0, s->in, s->out);
}

static double best_ms(void (*run)(tensors *, const shape *), tensors *t, const shape *s, int reps)
{
    run(t, s); /* warm-up: the pages touched, OpenBLAS's buffers allocated */
    double best = 1e300;
    for (int r = 0; r < reps; r++) {
        double t0 = bench_now_ms();
        run(t, s);
        double ms = bench_now_ms() - t0;
        if (ms < best) best = ms;
    }
    return best;
}

static float *uniform(tcb_rng *rng, size_t n)
{
    float *v = malloc(n * sizeof *v);
    if (!v) bench_die("bench_linear", "out of memory");
    for (size_t i = 0; i < n; i++) v[i] = (float)tcb_rng_uniform(rng) - 0.5f;
    return v;
}

int main(int argc, char **argv)
{
    int reps = argc > 1 ? bench_positive_int(argv[1], "reps", "top of bench/linear.c") : 5;
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 1, "bench/linear");
    printf("linear layers: row blocks per thread (tcbench) vs one OpenBLAS call, best of %d, %d thread(s)\n", reps,
           omp_get_max_threads());
    printf("%-24s %22s %12s %12s %8s %12s %12s %8s\n", "layer", "rows x in -> out", "fwd GF/s", "peer GF/s",
           "ratio", "bwd GF/s", "peer GF/s", "ratio");
    for (size_t k = 0; k < sizeof shapes / sizeof *shapes; k++) {
        const shape *s = &shapes[k];
        size_t nx = (size_t)s->rows * s->in, ny = (size_t)s->rows * s->out, nw = (size_t)s->in * s->out;
        tensors t = {uniform(&rng, nx), uniform(&rng, nw), uniform(&rng, s->out), uniform(&rng, ny),
                     uniform(&rng, ny), uniform(&rng, nx), uniform(&rng, nw)};
        double gf = 2.0 * s->rows * s->in * s->out * 1e-6; /* GFLOP·1e3: over ms gives GFLOP/s */
        double fs = best_ms(split_forward, &t, s, reps), fp = best_ms(peer_forward, &t, s, reps);
        double bs = best_ms(split_backward, &t, s, reps), bp = best_ms(peer_backward, &t, s, reps);
        char dims[64];
        snprintf(dims, sizeof dims, "%d x %d -> %d", s->rows, s->in, s->out);
        printf("%-24s %22s %12.1f %12.1f %8.2f %12.1f %12.1f %8.2f\n", s->name, dims, gf / fs, gf / fp, fp / fs,
               2 * gf / bs, 2 * gf / bp, bp / bs);
        free(t.x), free(t.W), free(t.b), free(t.y), free(t.dy), free(t.dx), free(t.dW);
    }
    return 0;
}
