/* methods/neupig/loss.c: the isometry term against a double reference
 * written here, its gradient by central differences, and the frame
 * confidence on a case worked out by hand. (The robust Chamfer:
 * test_robust_chamfer.) */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>

#include "methods/neupig/loss.h"
#include "tcb/rng.h"
#include "testutil.h"

#define FD_H 1e-6

static double sq(const double *a, const double *b)
{
    double s = 0.0;
    for (int k = 0; k < 3; k++) s += (a[k] - b[k]) * (a[k] - b[k]);
    return s;
}

static void test_confidence(void **state)
{
    (void)state;
    const double cd[5] = {3.0, 1.0, 0.5, 0.5, 2.5};
    double c[5];
    tcb_neupig_confidence(cd, 5, 2, 0, 100, c);
    assert_near(c[2], 1.0, 1e-15);
    assert_near(c[1], 2.0 / 3.0, 1e-15);
    assert_near(c[0], 2.0 / 3.0 * 2.0 / 7.0, 1e-15);
    assert_near(c[3], 1.0, 1e-15);
    assert_near(c[4], 1.0 / 3.0, 1e-15);
    tcb_neupig_confidence(cd, 5, 2, 25, 100, c); /* power 1 − √¼ = ½ */
    assert_near(c[0], sqrt(2.0 / 3.0) * sqrt(2.0 / 7.0), 1e-15);
    tcb_neupig_confidence(cd, 5, 2, 100, 100, c); /* the last epoch weighs every frame alike */
    for (int t = 0; t < 5; t++) assert_near(c[t], 1.0, 1e-15);
}

enum { T = 2, NV = 4, NE = 5 };

static double ref_edges(const double *X, const int32_t *edges, const float *base)
{
    double sum = 0.0;
    for (int t = 0; t < T; t++)
        for (int e = 0; e < NE; e++)
            sum += fabs(sqrt(sq(X + 3 * (t * NV + edges[2 * e]), X + 3 * (t * NV + edges[2 * e + 1]))) -
                        base[e]);
    return 100.0 * sum / (T * NE);
}

static void test_edge_l1(void **state)
{
    (void)state;
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 9, "neupig");
    const int32_t edges[2 * NE] = {0, 1, 1, 2, 2, 0, 2, 3, 3, 0};
    float X[3 * T * NV], base[NE], dX[3 * T * NV] = {0};
    tu_fill_uniform(&rng, X, 3 * T * NV, -1.0, 1.0);
    tu_fill_uniform(&rng, base, NE, 0.2, 1.5);
    double l = tcb_neupig_edge_l1(X, T, NV, edges, NE, base, 100.0, dX);
    double *xd = tu_to_double(X, 3 * T * NV);
    assert_near(l, ref_edges(xd, edges, base), 1e-9);
    for (int e = 0; e < 3 * T * NV; e++) {
        double keep = xd[e];
        xd[e] = keep + FD_H;
        double lp = ref_edges(xd, edges, base);
        xd[e] = keep - FD_H;
        double lm = ref_edges(xd, edges, base);
        xd[e] = keep;
        double fd = (lp - lm) / (2.0 * FD_H);
        assert_near(dX[e], fd, 1e-4 * fabs(fd) + 1e-6);
    }
    free(xd);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_confidence),
                                       cmocka_unit_test(test_edge_l1)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
