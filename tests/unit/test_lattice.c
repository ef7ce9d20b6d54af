/* neural/lattice.c against a double-precision reference written here from
 * PyTorch's grid_sample(align_corners=True, padding_mode="border") rules:
 * values at the nodes, linear functions reproduced exactly, the border
 * clamp, one node, and the backwards (in the values and in the points)
 * checked by central differences of the reference objective ℓ = Σ a·out
 * (and the values' as the forward's adjoint). */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>

#include "neural/lattice.h"
#include "tcb/rng.h"
#include "testutil.h"

#define FD_H 1e-6

static void ref_sample(const double *values, int r, int F, const float p[3], double *out)
{
    const double pd[3] = {p[0], p[1], p[2]};
    tu_ref_trilinear(values, r, F, pd, out);
}

static double ref_objective(const double *values, int r, int F, const float *pts, int n,
                            const double *a)
{
    double l = 0.0, out[8];
    for (int p = 0; p < n; p++) {
        ref_sample(values, r, F, pts + 3 * p, out);
        for (int f = 0; f < F; f++) l += a[p * F + f] * out[f];
    }
    return l;
}

enum { R = 5, F = 3, N = 40 };

static void random_case(tcb_rng *rng, float *values, float *pts)
{
    tu_fill_uniform(rng, values, (size_t)R * R * R * F, -1.0, 1.0);
    /* Inside the cube, outside it (the border clamp), and exactly on nodes. */
    tu_fill_uniform(rng, pts, 3 * (N - 8), -1.3, 1.3);
    for (int p = N - 8; p < N; p++)
        for (int a = 0; a < 3; a++) pts[3 * p + a] = -1.0f + 0.5f * (float)((p + a) % R);
}

static void test_forward_matches_reference(void **state)
{
    (void)state;
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 1, "lattice");
    float values[R * R * R * F], pts[3 * N], out[N * F] = {0};
    random_case(&rng, values, pts);
    tcb_lattice_forward(out, values, R, F, pts, N, 0.5f);
    double *vd = tu_to_double(values, R * R * R * F), ref[F];
    for (int p = 0; p < N; p++) {
        ref_sample(vd, R, F, pts + 3 * p, ref);
        for (int f = 0; f < F; f++) assert_near(out[p * F + f], 0.5 * ref[f], 1e-6);
    }
    free(vd);
}

/* Node values of a linear function are interpolated to that function,
 * clamped to the cube outside it. */
static void test_linear_exact(void **state)
{
    (void)state;
    float values[R * R * R], pts[3] = {0.3f, -0.71f, 1.6f}, out = 0.0f;
    for (int z = 0; z < R; z++)
        for (int y = 0; y < R; y++)
            for (int x = 0; x < R; x++) {
                double px = -1.0 + 2.0 * x / (R - 1), py = -1.0 + 2.0 * y / (R - 1),
                       pz = -1.0 + 2.0 * z / (R - 1);
                values[(z * R + y) * R + x] = (float)(2.0 * px - py + 0.5 * pz + 0.25);
            }
    tcb_lattice_forward(&out, values, R, 1, pts, 1, 1.0f);
    assert_near(out, 2.0 * 0.3 + 0.71 + 0.5 * 1.0 + 0.25, 1e-6);
}

static void test_backward(void **state)
{
    (void)state;
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 2, "lattice");
    float values[R * R * R * F], pts[3 * N], dout[N * F], grad[R * R * R * F] = {0};
    random_case(&rng, values, pts);
    tu_fill_uniform(&rng, dout, N * F, -1.0, 1.0);
    tcb_lattice_backward(grad, dout, R, F, pts, N, 0.5f);
    double *vd = tu_to_double(values, R * R * R * F), *ad = tu_to_double(dout, N * F);
    for (int e = 0; e < R * R * R * F; e++) {
        double keep = vd[e];
        vd[e] = keep + FD_H;
        double lp = ref_objective(vd, R, F, pts, N, ad);
        vd[e] = keep - FD_H;
        double lm = ref_objective(vd, R, F, pts, N, ad);
        vd[e] = keep;
        assert_near(grad[e], 0.5 * (lp - lm) / (2.0 * FD_H), 1e-5);
    }
    /* The adjoint identity <dout, S v> = <Sᵀ dout, v>. */
    float out[N * F] = {0};
    tcb_lattice_forward(out, values, R, F, pts, N, 0.5f);
    double lhs = 0.0, rhs = 0.0;
    for (int e = 0; e < N * F; e++) lhs += (double)dout[e] * out[e];
    for (int e = 0; e < R * R * R * F; e++) rhs += (double)grad[e] * values[e];
    assert_near(lhs, rhs, 1e-4);
    free(vd);
    free(ad);
}

/* The points' gradient against central differences of the reference in
 * the points, at points inside cells (off the cell walls, where the
 * sample has a kink) and outside the cube on some axes (zero there). */
static void test_backward_points(void **state)
{
    (void)state;
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 3, "lattice");
    float values[R * R * R * F], pts[3 * N], dout[N * F], dpts[3 * N] = {0};
    tu_fill_uniform(&rng, values, (size_t)R * R * R * F, -1.0, 1.0);
    for (int p = 0; p < N; p++)
        for (int a = 0; a < 3; a++) {
            /* a cell's middle part, or beyond the cube for every fifth point's y */
            int c = (int)(tcb_rng_uniform(&rng) * (R - 1));
            double off = 0.1 + 0.8 * tcb_rng_uniform(&rng);
            pts[3 * p + a] = (float)(-1.0 + 2.0 * (c + off) / (R - 1));
            if (a == 1 && p % 5 == 0) pts[3 * p + a] = p % 10 ? 1.2f : -1.4f;
        }
    tu_fill_uniform(&rng, dout, N * F, -1.0, 1.0);
    tcb_lattice_backward_points(dpts, dout, values, R, F, pts, N, 0.5f);
    double *vd = tu_to_double(values, R * R * R * F), out_p[F], out_m[F];
    for (int p = 0; p < N; p++)
        for (int a = 0; a < 3; a++) {
            double q[3] = {pts[3 * p], pts[3 * p + 1], pts[3 * p + 2]};
            q[a] += FD_H;
            tu_ref_trilinear(vd, R, F, q, out_p);
            q[a] -= 2 * FD_H;
            tu_ref_trilinear(vd, R, F, q, out_m);
            double fd = 0.0;
            for (int f = 0; f < F; f++) fd += dout[p * F + f] * (out_p[f] - out_m[f]) / (2 * FD_H);
            assert_near(dpts[3 * p + a], 0.5 * fd, 1e-4);
            if (a == 1 && p % 5 == 0) assert_true(dpts[3 * p + a] == 0.0f);
        }
    free(vd);
}

/* One node: its value everywhere, no gradient to the points. */
static void test_single_node(void **state)
{
    (void)state;
    float value[2] = {0.25f, -1.5f}, pts[6] = {0.3f, -0.9f, 2.0f, -1.0f, 1.0f, 0.0f}, out[4] = {0}, dv[2] = {0};
    float dout[4] = {1.0f, 2.0f, -1.0f, 0.5f}, dpts[6] = {0};
    tcb_lattice_forward(out, value, 1, 2, pts, 2, 1.0f);
    for (int p = 0; p < 2; p++) assert_true(out[2 * p] == 0.25f && out[2 * p + 1] == -1.5f);
    tcb_lattice_backward(dv, dout, 1, 2, pts, 2, 1.0f);
    assert_true(dv[0] == 0.0f && dv[1] == 2.5f);
    tcb_lattice_backward_points(dpts, dout, value, 1, 2, pts, 2, 1.0f);
    for (int k = 0; k < 6; k++) assert_true(dpts[k] == 0.0f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_forward_matches_reference),
                                       cmocka_unit_test(test_linear_exact),
                                       cmocka_unit_test(test_backward),
                                       cmocka_unit_test(test_backward_points),
                                       cmocka_unit_test(test_single_node)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
