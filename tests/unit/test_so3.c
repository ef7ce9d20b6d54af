/* neural/so3.c: the exponential is the rotation by |r| about r/|r| (a
 * point on the axis stays, a perpendicular one turns by the angle), R Rᵀ = I
 * and det R = 1, the Taylor branch meets the closed form at the threshold,
 * and the backward pass matches central differences on both branches. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>

#include "neural/so3.h"
#include "tcb/rng.h"

static void test_rotation(void **state)
{
    (void)state;
    const double angles[] = {0.0, 0.004, 0.0099999, 0.0100001, 0.7, 2.5, 3.1};
    for (unsigned k = 0; k < sizeof angles / sizeof *angles; k++) {
        double axis[3] = {0.48, -0.6, 0.64}; /* unit */
        float r[3], R[9];
        for (int i = 0; i < 3; i++) r[i] = (float)(angles[k] * axis[i]);
        tcb_so3_exp_forward(R, r, 1);
        /* orthonormal, det 1 */
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++) {
                double s = 0;
                for (int m = 0; m < 3; m++) s += (double)R[3 * i + m] * R[3 * j + m];
                assert_true(fabs(s - (i == j)) < 1e-6);
            }
        double det = R[0] * ((double)R[4] * R[8] - (double)R[5] * R[7]) - R[1] * ((double)R[3] * R[8] - (double)R[5] * R[6]) +
                     R[2] * ((double)R[3] * R[7] - (double)R[4] * R[6]);
        assert_true(fabs(det - 1) < 1e-6);
        /* the axis stays; u ⟂ axis turns by the angle: cos = u·Ru */
        double ra[3] = {0, 0, 0}, u[3] = {0.8, 0.0, -0.6}, ru[3] = {0, 0, 0}; /* u·axis = 0 */
        for (int i = 0; i < 3; i++)
            for (int m = 0; m < 3; m++) ra[i] += R[3 * i + m] * axis[m], ru[i] += R[3 * i + m] * u[m];
        for (int i = 0; i < 3; i++) assert_true(fabs(ra[i] - axis[i]) < 1e-6);
        assert_true(fabs(u[0] * ru[0] + u[1] * ru[1] + u[2] * ru[2] - cos(angles[k])) < 1e-6);
    }
}

static double loss(const float *r, const float *W)
{
    float R[9];
    tcb_so3_exp_forward(R, r, 1);
    double s = 0;
    for (int e = 0; e < 9; e++) s += (double)W[e] * R[e];
    return s;
}

static void test_gradient(void **state)
{
    (void)state;
    tcb_rng rng;
    tcb_rng_seed(&rng, 11);
    const double scales[] = {0.003, 0.3, 2.0};
    for (unsigned k = 0; k < 3; k++) {
        float r[3], W[9], dr[3];
        for (int i = 0; i < 3; i++) r[i] = (float)(scales[k] * tcb_rng_normal(&rng) / sqrt(3.0));
        for (int e = 0; e < 9; e++) W[e] = (float)tcb_rng_normal(&rng);
        tcb_so3_exp_backward(dr, W, r, 1);
        /* a step that keeps the small vector below the threshold */
        float eps = k == 0 ? 2e-4f : 1e-3f;
        for (int i = 0; i < 3; i++) {
            float keep = r[i];
            r[i] = keep + eps;
            double up = loss(r, W);
            r[i] = keep - eps;
            double down = loss(r, W);
            r[i] = keep;
            double fd = (up - down) / (2 * eps);
            assert_true(fabs(fd - dr[i]) < 2e-3 * (1 + fabs(fd)));
        }
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_rotation),
        cmocka_unit_test(test_gradient),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
