/* neural/rigid.c: the quaternion-and-translation motion against a double
 * reference written from the unit-quaternion rotation matrix (a different
 * formula from PyTorch3D's, equal for a unit quaternion), and its backward
 * against central differences of that reference. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>

#include "neural/rigid.h"
#include "tcb/rng.h"
#include "testutil.h"

enum { NX = 5, FR = 3, N = NX * FR };
#define FD_H 1e-6

/* y of one row, in double: normalise q exactly as the method does, then
 * the standard matrix of the unit quaternion w + xi + yj + zk. */
static void ref_row(const double o[7], const float x[3], double y[3])
{
    double q[4] = {1.0 + o[0], o[1], o[2], o[3]}, n = 0.0;
    for (int k = 0; k < 4; k++) n += q[k] * q[k];
    n = sqrt(n);
    double u[4];
    for (int k = 0; k < 4; k++) u[k] = q[k] / (n + 1e-8);
    double m = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2] + u[3] * u[3]);
    double w = u[0] / m, a = u[1] / m, b = u[2] / m, c = u[3] / m;
    double R[9] = {w * w + a * a - b * b - c * c, 2 * (a * b - w * c), 2 * (a * c + w * b),
                   2 * (a * b + w * c), w * w - a * a + b * b - c * c, 2 * (b * c - w * a),
                   2 * (a * c - w * b), 2 * (b * c + w * a), w * w - a * a - b * b + c * c};
    for (int r = 0; r < 3; r++)
        y[r] = R[3 * r] * x[0] + R[3 * r + 1] * x[1] + R[3 * r + 2] * x[2] + tanh(0.1 * o[4 + r]);
}

static void random_case(tcb_rng *rng, float *o, float *x, float *a)
{
    tu_fill_uniform(rng, o, 7 * N, -1.5, 1.5);
    tu_fill_uniform(rng, x, 3 * NX, -1.0, 1.0);
    tu_fill_uniform(rng, a, 3 * N, -1.0, 1.0);
}

static void test_identity_at_zero(void **state)
{
    (void)state;
    float o[7] = {0}, x[3] = {0.3f, -0.2f, 0.9f}, y[3];
    tcb_rigid_forward(y, o, x, 1, 1);
    for (int k = 0; k < 3; k++) assert_near(y[k], x[k], 1e-7);
}

static void test_forward(void **state)
{
    (void)state;
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 6, "rigid");
    float o[7 * N], x[3 * NX], a[3 * N], y[3 * N];
    random_case(&rng, o, x, a);
    tcb_rigid_forward(y, o, x, N, NX);
    for (int p = 0; p < N; p++) {
        double od[7], ref[3];
        for (int k = 0; k < 7; k++) od[k] = o[7 * p + k];
        ref_row(od, x + 3 * (p % NX), ref);
        for (int k = 0; k < 3; k++) assert_near(y[3 * p + k], ref[k], 1e-6);
    }
}

/* ℓ = Σ a·y; |g − fd| ≤ 1e-4·|fd| + 1e-6. */
static void test_backward(void **state)
{
    (void)state;
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 7, "rigid");
    float o[7 * N], x[3 * NX], a[3 * N], g[7 * N];
    random_case(&rng, o, x, a);
    tcb_rigid_backward(g, a, o, x, N, NX);
    for (int p = 0; p < N; p++)
        for (int k = 0; k < 7; k++) {
            double od[7], yp[3], ym[3];
            for (int j = 0; j < 7; j++) od[j] = o[7 * p + j];
            od[k] += FD_H;
            ref_row(od, x + 3 * (p % NX), yp);
            od[k] -= 2 * FD_H;
            ref_row(od, x + 3 * (p % NX), ym);
            double fd = 0.0;
            for (int r = 0; r < 3; r++) fd += a[3 * p + r] * (yp[r] - ym[r]) / (2 * FD_H);
            assert_near(g[7 * p + k], fd, 1e-4 * fabs(fd) + 1e-6);
        }
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_identity_at_zero),
                                       cmocka_unit_test(test_forward), cmocka_unit_test(test_backward)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
