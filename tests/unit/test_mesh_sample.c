/* neural/mesh_sample.c: faces drawn in proportion to their area, points
 * uniform over each triangle (their mean its centroid), unit face normals
 * in the winding's direction, and the backward pass against central
 * differences of the points and normals with the draws held. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "neural/mesh_sample.h"
#include "tcb/rng.h"

/* Two triangles in the z = 0 plane, areas 1/2 and 3/2, wound upward. */
static const float V[5 * 3] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 4, 0, 0, 4, 1, 0};
static const int32_t F[2 * 3] = {0, 1, 2, 1, 3, 4};

static void test_draws(void **state)
{
    (void)state;
    enum { M = 40000 };
    tcb_mesh_draw *d = malloc(M * sizeof *d);
    float *p = malloc(M * 3 * sizeof *p), *n = malloc(M * 3 * sizeof *n);
    tcb_rng rng;
    tcb_rng_seed(&rng, 5);
    tcb_error err = {0};
    assert_int_equal(tcb_mesh_sample_draw(V, F, 2, M, &rng, d, &err), TCB_OK);
    tcb_mesh_sample_forward(V, F, d, M, p, n);
    int on_second = 0;
    double mean[2][3] = {{0}};
    for (int i = 0; i < M; i++) {
        int f = d[i].face;
        on_second += f;
        assert_true(d[i].w[0] >= 0 && d[i].w[1] >= 0 && d[i].w[2] >= 0);
        assert_float_equal(d[i].w[0] + d[i].w[1] + d[i].w[2], 1, 1e-6);
        for (int c = 0; c < 3; c++) mean[f][c] += p[3 * i + c];
        assert_float_equal(n[3 * i], 0, 0), assert_float_equal(n[3 * i + 1], 0, 0);
        assert_float_equal(n[3 * i + 2], 1, 1e-7);
    }
    /* 3/4 of the area: binomial sd √(M·3/16) ≈ 87 */
    assert_true(abs(on_second - 3 * M / 4) < 450);
    const double centroid[2][2] = {{1.0 / 3, 1.0 / 3}, {3.0, 1.0 / 3}};
    for (int f = 0; f < 2; f++) {
        int count = f ? on_second : M - on_second;
        for (int c = 0; c < 2; c++) assert_true(fabs(mean[f][c] / count - centroid[f][c]) < 0.02);
    }
    /* no area, no samples */
    static const float flat[9] = {0, 0, 0, 1, 0, 0, 2, 0, 0};
    assert_int_equal(tcb_mesh_sample_draw(flat, F, 1, 10, &rng, d, &err), TCB_ERR_NUMERIC);
    free(d), free(p), free(n);
}

/* Σ gp·x + Σ gn·n over the samples */
static double objective(const float *v, const tcb_mesh_draw *d, int m, const float *gp, const float *gn)
{
    float p[3 * 64], n[3 * 64];
    tcb_mesh_sample_forward(v, F, d, m, p, n);
    double s = 0;
    for (int i = 0; i < 3 * m; i++) s += (double)gp[i] * p[i] + (double)gn[i] * n[i];
    return s;
}

static void test_gradient(void **state)
{
    (void)state;
    enum { M = 64 };
    tcb_rng rng;
    tcb_rng_seed(&rng, 8);
    float v[15], gp[3 * M], gn[3 * M], dv[15] = {0}, face_grad[6];
    for (int i = 0; i < 15; i++) v[i] = V[i] + (float)(0.2 * tcb_rng_normal(&rng));
    for (int i = 0; i < 3 * M; i++) gp[i] = (float)tcb_rng_normal(&rng), gn[i] = (float)tcb_rng_normal(&rng);
    tcb_mesh_draw d[M];
    tcb_error err = {0};
    assert_int_equal(tcb_mesh_sample_draw(v, F, 2, M, &rng, d, &err), TCB_OK);
    tcb_mesh_sample_backward(v, F, 2, d, M, gp, gn, face_grad, dv);
    const float eps = 1e-3f;
    for (int i = 0; i < 15; i++) {
        float keep = v[i];
        v[i] = keep + eps;
        double up = objective(v, d, M, gp, gn);
        v[i] = keep - eps;
        double down = objective(v, d, M, gp, gn);
        v[i] = keep;
        double fd = (up - down) / (2 * eps);
        assert_true(fabs(fd - dv[i]) < 2e-3 * (1 + fabs(fd)));
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_draws),
        cmocka_unit_test(test_gradient),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
