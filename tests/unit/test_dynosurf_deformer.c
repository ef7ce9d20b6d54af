/* methods/dynosurf/deformer.c: the control points are distinct grid
 * vertices; the blend weights a softmax (positive, summing to 1) and the
 * Gaussian target peaked at its control point; identity transforms carry
 * every point to itself; the blend of rigid motions' gradient in the
 * weights, rotations and translations against central differences. The
 * gradients through the two networks, the encoding and the so(3)
 * exponential to the control points are held to PyTorch in float64
 * (tests/pytorch/dynosurf_deformer_check.py): central differences of float
 * networks with ReLUs are too noisy to tell 1e-4. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "methods/dynosurf/deformer.h"
#include "tcb/rng.h"

enum { K = DYNO_CONTROL_POINTS, NV = 300, N = 24 };

typedef struct fixture {
    float *params, grid[3 * NV], x[3 * N];
    dyno_deformer d;
    dyno_blend b;
} fixture;

static void uniform(tcb_rng *rng, float *v, int n, double half)
{
    for (int i = 0; i < n; i++) v[i] = (float)(half * (2 * tcb_rng_uniform(rng) - 1));
}

static fixture *setup_fixture(void)
{
    fixture *fx = calloc(1, sizeof *fx);
    size_t P = dyno_deformer_size();
    fx->params = malloc(P * sizeof(float));
    dyno_deformer_bind(&fx->d, fx->params);
    tcb_rng rng;
    tcb_rng_seed(&rng, 21);
    uniform(&rng, fx->grid, 3 * NV, 0.5);
    tcb_error err = {0};
    assert_int_equal(dyno_deformer_init(&fx->d, fx->grid, NV, &rng, &err), TCB_OK);
    uniform(&rng, fx->x, 3 * N, 0.5);
    assert_int_equal(dyno_blend_alloc(&fx->b, N, &err), TCB_OK);
    return fx;
}

static void free_fixture(fixture *fx)
{
    dyno_blend_free(&fx->b);
    free(fx->params), free(fx);
}

static void test_init_and_weights(void **state)
{
    (void)state;
    fixture *fx = setup_fixture();
    for (int k = 0; k < K; k++) {
        int found = 0;
        for (int v = 0; v < NV; v++) found += !memcmp(fx->d.control + 3 * k, fx->grid + 3 * v, 3 * sizeof(float));
        assert_int_equal(found, 1);
        for (int j = 0; j < k; j++) assert_memory_not_equal(fx->d.control + 3 * k, fx->d.control + 3 * j, 12);
    }
    dyno_blend_forward(&fx->d, &fx->b, fx->x, N);
    for (int i = 0; i < N; i++) {
        double s = 0;
        for (int k = 0; k < K; k++) assert_true(fx->b.w[i * K + k] > 0), s += fx->b.w[i * K + k];
        assert_float_equal(s, 1, 1e-5);
    }
    float w[K * K];
    dyno_blend_gaussian(&fx->d, fx->d.control, K, w);
    for (int k = 0; k < K; k++)
        for (int j = 0; j < K; j++) assert_true(j == k || w[k * K + j] < w[k * K + k]);
    /* zero transforms: every point stays */
    float R[9 * K], raw[6 * K] = {0}, X[3 * N];
    for (int k = 0; k < K; k++)
        for (int a = 0; a < 9; a++) R[9 * k + a] = a % 4 == 0;
    dyno_deform_apply(fx->x, N, fx->b.w, R, raw, X);
    for (int i = 0; i < 3 * N; i++) assert_float_equal(X[i], fx->x[i], 1e-6);
    free_fixture(fx);
}

/* Σ g · deform(x) for one frame's w, R, raw, in double. */
static double apply_loss(const float *x, const float *w, const float *R, const float *raw, const float *g)
{
    float X[3 * N];
    dyno_deform_apply(x, N, w, R, raw, X);
    double L = 0;
    for (int i = 0; i < 3 * N; i++) L += (double)g[i] * X[i];
    return L;
}

/* The blend of rigid motions is linear in each of w, R and T: central
 * differences are exact up to rounding, entry by entry. */
static void test_apply_gradient(void **state)
{
    (void)state;
    tcb_rng rng;
    tcb_rng_seed(&rng, 17);
    float x[3 * N], w[N * K], R[9 * K], raw[6 * K], g[3 * N];
    float dw[N * K] = {0}, dR[9 * K] = {0}, draw[6 * K] = {0};
    uniform(&rng, x, 3 * N, 0.5), uniform(&rng, R, 9 * K, 1.0), uniform(&rng, raw, 6 * K, 0.3);
    uniform(&rng, g, 3 * N, 1.0);
    for (int i = 0; i < N; i++) {
        double s = 0;
        for (int k = 0; k < K; k++) s += w[i * K + k] = (float)tcb_rng_uniform(&rng);
        for (int k = 0; k < K; k++) w[i * K + k] /= (float)s;
    }
    dyno_deform_apply_backward(x, N, w, R, raw, g, dR, draw, dw);
    const float eps = 1e-2f;
    struct { float *v, *d; int n; } blocks[3] = {{w, dw, N * K}, {R, dR, 9 * K}, {raw, draw, 6 * K}};
    for (int b = 0; b < 3; b++)
        for (int i = 0; i < blocks[b].n; i++) {
            if (b == 2 && i % 6 < 3) { /* the axis-angle part reaches X only through R */
                assert_float_equal(draw[i], 0, 0);
                continue;
            }
            float keep = blocks[b].v[i];
            blocks[b].v[i] = keep + eps;
            double up = apply_loss(x, w, R, raw, g);
            blocks[b].v[i] = keep - eps;
            double down = apply_loss(x, w, R, raw, g);
            blocks[b].v[i] = keep;
            double fd = (up - down) / (2 * eps);
            assert_true(fabs(fd - blocks[b].d[i]) < 1e-4 * (1 + fabs(fd)));
        }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_init_and_weights),
        cmocka_unit_test(test_apply_gradient),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
