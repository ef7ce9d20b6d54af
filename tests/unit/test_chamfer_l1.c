/* neural/chamfer_l1.c: the L1-nearest neighbour against a scan of every
 * point (on clouds where the L2-nearest often differs), the Chamfer and
 * normal terms against a direct O(n²) computation, and their gradients
 * against central differences with the neighbours held. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "neural/chamfer_l1.h"
#include "tcb/rng.h"

enum { NX = 60, NY = 300 };

static double l1(const float *a, const float *b)
{
    return fabs((double)a[0] - b[0]) + fabs((double)a[1] - b[1]) + fabs((double)a[2] - b[2]);
}

static int scan_l1(const float *pts, int n, const float *q)
{
    int arg = 0;
    for (int i = 1; i < n; i++)
        if (l1(pts + 3 * i, q) < l1(pts + 3 * arg, q)) arg = i;
    return arg;
}

static int scan_l2(const float *pts, int n, const float *q)
{
    int arg = 0;
    double best = INFINITY;
    for (int i = 0; i < n; i++) {
        double s = 0;
        for (int c = 0; c < 3; c++) s += ((double)pts[3 * i + c] - q[c]) * ((double)pts[3 * i + c] - q[c]);
        if (s < best) best = s, arg = i;
    }
    return arg;
}

static void fill(tcb_rng *rng, float *p, int n, double scale)
{
    for (int i = 0; i < 3 * n; i++) p[i] = (float)(scale * tcb_rng_normal(rng));
}

static void unit_normals(tcb_rng *rng, float *nrm, int n)
{
    for (int i = 0; i < n; i++) {
        double v[3] = {tcb_rng_normal(rng), tcb_rng_normal(rng), tcb_rng_normal(rng)};
        double len = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        for (int c = 0; c < 3; c++) nrm[3 * i + c] = (float)(v[c] / len);
    }
}

static void test_nearest(void **state)
{
    (void)state;
    enum { N = 2000, Q = 3000 };
    tcb_rng rng;
    tcb_rng_seed(&rng, 1);
    float *p = malloc(N * 3 * sizeof *p), *q = malloc(Q * 3 * sizeof *q), *d1 = malloc(Q * sizeof *d1);
    int32_t *idx = malloc(Q * sizeof *idx);
    fill(&rng, p, N, 1.0);
    fill(&rng, q, Q, 1.5);
    tcb_nn *index;
    tcb_error err = {0};
    assert_int_equal(tcb_nn_build(p, N, &index, &err), TCB_OK);
    assert_int_equal(tcb_nearest_l1(index, p, N, q, Q, idx, d1, &err), TCB_OK);
    int differ = 0;
    for (int i = 0; i < Q; i++) {
        int want = scan_l1(p, N, q + 3 * i);
        assert_int_equal(idx[i], want);
        assert_float_equal(d1[i], l1(p + 3 * want, q + 3 * i), 1e-6);
        differ += scan_l2(p, N, q + 3 * i) != want;
    }
    assert_true(differ > Q / 20); /* the metric matters on these clouds */
    tcb_nn_free(index);
    free(p), free(q), free(d1), free(idx);
}

/* the loss as its definition reads, by scanning */
static void direct(const float *X, const float *NX_, const float *Y, const float *NY_, double *cham, double *normal)
{
    *cham = *normal = 0;
    for (int pass = 0; pass < 2; pass++) {
        const float *A = pass ? Y : X, *NA = pass ? NY_ : NX_, *B = pass ? X : Y, *NB = pass ? NX_ : NY_;
        int na = pass ? NY : NX, nb = pass ? NX : NY;
        for (int i = 0; i < na; i++) {
            int j = scan_l1(B, nb, A + 3 * i);
            *cham += l1(A + 3 * i, B + 3 * j) / na;
            double c = 0;
            for (int d = 0; d < 3; d++) c += (double)NA[3 * i + d] * NB[3 * j + d];
            *normal += (1 - fabs(c)) / na;
        }
    }
}

static void test_value_and_gradient(void **state)
{
    (void)state;
    tcb_rng rng;
    tcb_rng_seed(&rng, 4);
    float X[3 * NX], NXs[3 * NX], Y[3 * NY], NYs[3 * NY], dX[3 * NX], dNX[3 * NX];
    fill(&rng, X, NX, 1.0), fill(&rng, Y, NY, 1.0);
    unit_normals(&rng, NXs, NX), unit_normals(&rng, NYs, NY);
    tcb_nn *index;
    tcb_error err = {0};
    assert_int_equal(tcb_nn_build(Y, NY, &index, &err), TCB_OK);
    double cham, normal, want_cham, want_normal;
    assert_int_equal(tcb_chamfer_l1(X, NXs, NX, Y, NYs, NY, index, &cham, &normal, dX, dNX, &err), TCB_OK);
    direct(X, NXs, Y, NYs, &want_cham, &want_normal);
    assert_float_equal(cham, want_cham, 1e-6);
    assert_float_equal(normal, want_normal, 1e-6);
    /* central differences of cham in X and of normal in NX; a step that
     * changes a neighbour or crosses a kink of |·| would not be a
     * derivative: the step is small against the gaps of these clouds */
    const float eps = 1e-4f;
    float scratch[3 * NX], scratch_n[3 * NX];
    for (int i = 0; i < 3 * NX; i++) {
        for (int which = 0; which < 2; which++) {
            float *v = which ? NXs : X, keep = v[i];
            double up_c, up_n, down_c, down_n;
            v[i] = keep + eps;
            tcb_chamfer_l1(X, NXs, NX, Y, NYs, NY, index, &up_c, &up_n, scratch, scratch_n, &err);
            v[i] = keep - eps;
            tcb_chamfer_l1(X, NXs, NX, Y, NYs, NY, index, &down_c, &down_n, scratch, scratch_n, &err);
            v[i] = keep;
            double fd = which ? (up_n - down_n) / (2 * eps) : (up_c - down_c) / (2 * eps);
            double got = which ? dNX[i] : dX[i];
            assert_true(fabs(fd - got) < 2e-3 * (1 + fabs(fd)));
        }
    }
    tcb_nn_free(index);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_nearest),
        cmocka_unit_test(test_value_and_gradient),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
