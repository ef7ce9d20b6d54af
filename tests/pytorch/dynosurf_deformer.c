/* Helper of dynosurf_deformer_check.py: DynoSurf's deformer
 * (methods/dynosurf/deformer.c) initialised on random grid vertices: the
 * blend weights of N points, the transforms of three frames, the deformed
 * points, and the gradient of Σ gX·X + Σ graw·raw in every parameter; then
 * the blend pretraining's loss and gradient on N other points. Writes into
 * DIR (float32, host order):
 *   params.bin [P]  x.bin [N][3]  w.bin [N][K]  raw.bin [F][K][6]
 *   X.bin [F][N][3]  gX.bin [F][N][3]  graw.bin [F][K][6]  grad.bin [P]
 *   x2.bin [N][3]  pre_grad.bin [P]  meta.json {P, K, N, F, frames, blend_offset, pre_loss}
 * usage: dynosurf_deformer N SEED DIR */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "methods/dynosurf/deformer.h"
#include "tcb/rng.h"
#include "tests/pytorch/export.h"

enum { K = DYNO_CONTROL_POINTS, NV = 500, F = 3 };
static const int frames[F] = {0, 5, 16};

static int fail(const tcb_error *err)
{
    fprintf(stderr, "dynosurf_deformer: %s\n", err->msg);
    return 1;
}

static void uniform(tcb_rng *rng, float *v, size_t n)
{
    for (size_t i = 0; i < n; i++) v[i] = (float)(tcb_rng_uniform(rng) - 0.5);
}

int main(int argc, char **argv)
{
    if (argc != 4) {
        fprintf(stderr, "usage: dynosurf_deformer N SEED DIR\n");
        return 2;
    }
    int n = atoi(argv[1]);
    const char *dir = argv[3];
    tcb_rng rng;
    tcb_rng_seed(&rng, (uint64_t)atoll(argv[2]));
    size_t P = dyno_deformer_size();
    float *params = malloc(P * sizeof *params), *grad = calloc(P, sizeof *grad), *pre_grad = calloc(P, sizeof *grad);
    float *grid = malloc(NV * 3 * sizeof *grid), *x = malloc((size_t)n * 3 * sizeof *x);
    float *x2 = malloc((size_t)n * 3 * sizeof *x2), *X = malloc((size_t)F * n * 3 * sizeof *X);
    float *gX = malloc((size_t)F * n * 3 * sizeof *gX), *graw = malloc(F * K * 6 * sizeof *graw);
    dyno_deformer d, g, gp;
    dyno_deformer_bind(&d, params), dyno_deformer_bind(&g, grad), dyno_deformer_bind(&gp, pre_grad);
    uniform(&rng, grid, NV * 3);
    tcb_error err = {0};
    if (dyno_deformer_init(&d, grid, NV, &rng, &err)) return fail(&err);
    uniform(&rng, x, (size_t)n * 3), uniform(&rng, x2, (size_t)n * 3);
    for (size_t i = 0; i < (size_t)F * n * 3; i++) gX[i] = (float)tcb_rng_normal(&rng);
    for (size_t i = 0; i < F * K * 6; i++) graw[i] = (float)tcb_rng_normal(&rng);

    dyno_blend b;
    dyno_transforms tr;
    if (dyno_blend_alloc(&b, n, &err) || dyno_transforms_alloc(&tr, F, &err)) return fail(&err);
    dyno_blend_forward(&d, &b, x, n);
    dyno_transforms_forward(&d, &tr, frames, F);
    memcpy(tr.draw, graw, F * K * 6 * sizeof *graw);
    memset(tr.dR, 0, F * K * 9 * sizeof *tr.dR);
    memset(b.dw, 0, (size_t)n * K * sizeof *b.dw);
    for (int f = 0; f < F; f++) {
        dyno_deform_apply(x, n, b.w, tr.R + 9 * K * f, tr.raw + 6 * K * f, X + (size_t)3 * n * f);
        dyno_deform_apply_backward(x, n, b.w, tr.R + 9 * K * f, tr.raw + 6 * K * f, gX + (size_t)3 * n * f,
                                   tr.dR + 9 * K * f, tr.draw + 6 * K * f, b.dw);
    }
    int rc = export_f32(dir, "params.bin", params, P) | export_f32(dir, "x.bin", x, (size_t)n * 3) |
             export_f32(dir, "w.bin", b.w, (size_t)n * K) | export_f32(dir, "raw.bin", tr.raw, F * K * 6) |
             export_f32(dir, "X.bin", X, (size_t)F * n * 3) | export_f32(dir, "gX.bin", gX, (size_t)F * n * 3) |
             export_f32(dir, "graw.bin", graw, F * K * 6) | export_f32(dir, "x2.bin", x2, (size_t)n * 3);
    dyno_transforms_backward(&d, &g, &tr);
    dyno_blend_backward(&d, &g, &b);
    double pre_loss = dyno_blend_pretrain_loss(&d, &gp, &b, x2, n);
    rc |= export_f32(dir, "grad.bin", grad, P) | export_f32(dir, "pre_grad.bin", pre_grad, P);
    char path[EXPORT_PATH_MAX];
    rc |= export_path(path, dir, "meta.json");
    FILE *fp = rc ? NULL : fopen(path, "w");
    if (!fp) return 1;
    fprintf(fp, "{\"P\": %zu, \"K\": %d, \"N\": %d, \"F\": %d, \"frames\": [%d, %d, %d], \"blend_offset\": %zu, "
                "\"pre_loss\": %.17g}\n",
            P, K, n, F, frames[0], frames[1], frames[2], dyno_deformer_blend_offset(), pre_loss);
    rc |= fclose(fp) != 0;
    dyno_blend_free(&b), dyno_transforms_free(&tr);
    free(params), free(grad), free(pre_grad), free(grid), free(x), free(x2), free(X), free(gX), free(graw);
    return rc;
}
