/* Helper of dynosurf_shape_check.py: DynoSurf's shape network
 * (methods/dynosurf/shape.c) on random vertices with PyTorch's default
 * initialisation, forward, read-out and backward for random upstream
 * gradients. Writes into DIR (float32, host order):
 *     params.bin [P]  x.bin [n][3]  out.bin [n][4]  sdf.bin [n]  v.bin [n][3]
 *     dsdf.bin [n]  dv.bin [n][3]  grad.bin [P]
 * usage: dynosurf_shape N EDGE SEED DIR */
#include <stdio.h>
#include <stdlib.h>

#include "methods/dynosurf/shape.h"
#include "tcb/rng.h"
#include "tests/pytorch/export.h"

int main(int argc, char **argv)
{
    if (argc != 5) {
        fprintf(stderr, "usage: dynosurf_shape N EDGE SEED DIR\n");
        return 2;
    }
    int n = atoi(argv[1]);
    float edge = (float)atof(argv[2]);
    const char *dir = argv[4];
    tcb_rng rng;
    tcb_rng_seed(&rng, (uint64_t)atoll(argv[3]));
    size_t P = dyno_shape_size();
    float *params = malloc(P * sizeof *params), *gparams = calloc(P, sizeof *gparams);
    float *x = malloc((size_t)n * 3 * sizeof *x), *sdf = malloc((size_t)n * sizeof *sdf);
    float *v = malloc((size_t)n * 3 * sizeof *v), *dsdf = malloc((size_t)n * sizeof *dsdf);
    float *dv = malloc((size_t)n * 3 * sizeof *dv), *dout = malloc((size_t)n * 4 * sizeof *dout);
    dyno_shape s, g;
    dyno_shape_bind(&s, params);
    dyno_shape_bind(&g, gparams);
    dyno_shape_init(&s, &rng);
    for (int i = 0; i < 3 * n; i++) x[i] = (float)(tcb_rng_uniform(&rng) - 0.5);
    for (int i = 0; i < n; i++) dsdf[i] = (float)tcb_rng_normal(&rng);
    for (int i = 0; i < 3 * n; i++) dv[i] = (float)tcb_rng_normal(&rng);
    dyno_shape_acts a;
    tcb_error err = {0};
    if (dyno_shape_acts_alloc(&a, n, &err)) {
        fprintf(stderr, "%s\n", err.msg);
        return 1;
    }
    dyno_shape_forward(&s, &a, x);
    dyno_shape_readout(a.out, x, n, edge, sdf, v);
    dyno_shape_readout_backward(a.out, n, edge, dsdf, dv, dout);
    dyno_shape_backward(&s, &g, &a, dout);
    int rc = export_f32(dir, "params.bin", params, P) | export_f32(dir, "x.bin", x, (size_t)n * 3) |
             export_f32(dir, "out.bin", a.out, (size_t)n * 4) | export_f32(dir, "sdf.bin", sdf, (size_t)n) |
             export_f32(dir, "v.bin", v, (size_t)n * 3) | export_f32(dir, "dsdf.bin", dsdf, (size_t)n) |
             export_f32(dir, "dv.bin", dv, (size_t)n * 3) | export_f32(dir, "grad.bin", gparams, P);
    dyno_shape_acts_free(&a);
    free(params), free(gparams), free(x), free(sdf), free(v), free(dsdf), free(dv), free(dout);
    return rc;
}
