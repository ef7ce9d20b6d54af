/* neural/approx_sdf.c: the value against a direct computation of the
 * softmax of Gaussians over the k nearest points (found here by sorting all
 * distances), its sign on either side of a plane of points, and the
 * backward pass against central differences; bad k refused. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "neural/approx_sdf.h"
#include "tcb/rng.h"

enum { N = 400, M = 30, K = TCB_APPROX_SDF_K };
static const double R = TCB_APPROX_SDF_RADIUS;

/* points on the unit sphere's upper cap, outward normals, jittered */
static void cloud(tcb_rng *rng, float *p, float *nrm)
{
    for (int i = 0; i < N; i++) {
        double v[3] = {tcb_rng_normal(rng), tcb_rng_normal(rng), fabs(tcb_rng_normal(rng))}, len = 0;
        for (int c = 0; c < 3; c++) len += v[c] * v[c];
        len = sqrt(len);
        for (int c = 0; c < 3; c++) p[3 * i + c] = (float)(v[c] / len), nrm[3 * i + c] = (float)(v[c] / len);
    }
}

static int cmp_pair(const void *a, const void *b)
{
    const double *x = a, *y = b;
    return (x[0] > y[0]) - (x[0] < y[0]);
}

static double direct(const float *y, const float *p, const float *nrm)
{
    double (*d)[2] = malloc(sizeof(double[2]) * N);
    for (int i = 0; i < N; i++) {
        double s = 0;
        for (int c = 0; c < 3; c++) s += ((double)y[c] - p[3 * i + c]) * ((double)y[c] - p[3 * i + c]);
        d[i][0] = s, d[i][1] = i;
    }
    qsort(d, N, sizeof *d, cmp_pair);
    double g[K], z = 0, s = 0;
    for (int j = 0; j < K; j++) z += g[j] = exp(exp(-d[j][0] / (R * R)));
    for (int j = 0; j < K; j++) {
        int i = (int)d[j][1];
        double l = 0;
        for (int c = 0; c < 3; c++) l += nrm[3 * i + c] * ((double)y[c] - p[3 * i + c]);
        s += g[j] / z * l;
    }
    free(d);
    return s;
}

static void test_value_and_sign(void **state)
{
    (void)state;
    tcb_rng rng;
    tcb_rng_seed(&rng, 3);
    float p[3 * N], nrm[3 * N], y[3 * M], s[M];
    int32_t nbr[M * K];
    cloud(&rng, p, nrm);
    for (int q = 0; q < M; q++) { /* along a point's normal, in or out */
        int i = (int)tcb_rng_below(&rng, N);
        double t = (q % 2 ? 0.05 : -0.05) * (1 + tcb_rng_uniform(&rng));
        for (int c = 0; c < 3; c++) y[3 * q + c] = (float)(p[3 * i + c] * (1 + t));
    }
    tcb_nn *index;
    tcb_error err = {0};
    assert_int_equal(tcb_nn_build(p, N, &index, &err), TCB_OK);
    assert_int_equal(tcb_approx_sdf_forward(s, nbr, y, M, index, p, nrm, K, R, &err), TCB_OK);
    for (int q = 0; q < M; q++) {
        assert_true(fabs(s[q] - direct(y + 3 * q, p, nrm)) < 1e-6);
        assert_true(q % 2 ? s[q] > 0 : s[q] < 0);
    }
    assert_int_equal(tcb_approx_sdf_forward(s, nbr, y, M, index, p, nrm, TCB_APPROX_SDF_K_MAX + 1, R, &err),
                     TCB_ERR_INPUT);
    tcb_nn_free(index);
}

static void test_gradient(void **state)
{
    (void)state;
    tcb_rng rng;
    tcb_rng_seed(&rng, 9);
    float p[3 * N], nrm[3 * N], y[3 * M], s[M], ds[M], dy[3 * M];
    int32_t nbr[M * K], nbr2[M * K];
    cloud(&rng, p, nrm);
    for (int i = 0; i < 3 * M; i++) y[i] = (float)(0.6 * tcb_rng_normal(&rng));
    for (int q = 0; q < M; q++) ds[q] = (float)tcb_rng_normal(&rng);
    tcb_nn *index;
    tcb_error err = {0};
    assert_int_equal(tcb_nn_build(p, N, &index, &err), TCB_OK);
    assert_int_equal(tcb_approx_sdf_forward(s, nbr, y, M, index, p, nrm, K, R, &err), TCB_OK);
    tcb_approx_sdf_backward(dy, ds, y, M, nbr, p, nrm, K, R);
    /* central differences of Σ ds·s with the neighbours held (a step that
     * changes them is skipped: the choice has no gradient) */
    const float eps = 1e-3f;
    int checked = 0;
    for (int i = 0; i < 3 * M; i++) {
        int q = i / 3;
        float keep = y[i], up, down;
        y[i] = keep + eps;
        assert_int_equal(tcb_approx_sdf_forward(&up, nbr2, y + 3 * q, 1, index, p, nrm, K, R, &err), TCB_OK);
        int same = !memcmp(nbr2, nbr + q * K, sizeof(int32_t) * K);
        y[i] = keep - eps;
        assert_int_equal(tcb_approx_sdf_forward(&down, nbr2, y + 3 * q, 1, index, p, nrm, K, R, &err), TCB_OK);
        same &= !memcmp(nbr2, nbr + q * K, sizeof(int32_t) * K);
        y[i] = keep;
        if (!same) continue;
        double fd = ds[q] * ((double)up - down) / (2 * eps);
        assert_true(fabs(fd - dy[i]) < 2e-3 * (1 + fabs(fd)));
        checked++;
    }
    assert_true(checked > 2 * M);
    tcb_nn_free(index);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_value_and_sign),
        cmocka_unit_test(test_gradient),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
