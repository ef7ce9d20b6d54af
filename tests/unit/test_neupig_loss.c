/* methods/neupig/loss.c: the robust Chamfer and the isometry term against
 * double references written here (brute-force nearest neighbours), their
 * gradients by central differences of those references (the Welsch weights
 * held at their values, as the method detaches them), and the frame
 * confidence on a case worked out by hand. */
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
enum { NX = 30, NP = 40 };

static double sq(const double *a, const double *b)
{
    double s = 0.0;
    for (int k = 0; k < 3; k++) s += (a[k] - b[k]) * (a[k] - b[k]);
    return s;
}

/* One direction: Σ_q w_q · min_t |q − t|²; w NULL: compute the Welsch
 * weights into w_out instead of using frozen ones. */
static double ref_way(const double *q, int nq, const double *to, int nt, const double *w,
                      double *w_out)
{
    double sum = 0.0;
    for (int i = 0; i < nq; i++) {
        double best = INFINITY;
        for (int j = 0; j < nt; j++) best = fmin(best, sq(q + 3 * i, to + 3 * j));
        double wi = w ? w[i] : exp(-best * best / (2.0 * 0.3 * 0.3));
        if (w_out) w_out[i] = wi;
        sum += wi * best;
    }
    return sum;
}

static void test_chamfer(void **state)
{
    (void)state;
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 8, "neupig");
    float X[3 * NX], P[3 * NP], dX[3 * NX];
    tu_fill_uniform(&rng, X, 3 * NX, -0.5, 0.5);
    tu_fill_uniform(&rng, P, 3 * NP, -0.6, 0.6);
    tcb_nn *index;
    tcb_error err = {0};
    assert_int_equal(tcb_nn_build(P, NP, &index, &err), TCB_OK);
    double cd;
    assert_int_equal(tcb_neupig_chamfer(X, NX, P, NP, index, 0.3, &cd, dX, &err), TCB_OK);
    double *xd = tu_to_double(X, 3 * NX), *pd = tu_to_double(P, 3 * NP), wx[NX], wp[NP];
    double ref = ref_way(xd, NX, pd, NP, NULL, wx) + ref_way(pd, NP, xd, NX, NULL, wp);
    assert_near(cd, ref, 1e-6 * ref);
    for (int e = 0; e < 3 * NX; e++) {
        double keep = xd[e], l[2];
        for (int s = 0; s < 2; s++) {
            xd[e] = keep + (s ? -FD_H : FD_H);
            l[s] = ref_way(xd, NX, pd, NP, wx, NULL) + ref_way(pd, NP, xd, NX, wp, NULL);
        }
        xd[e] = keep;
        double fd = (l[0] - l[1]) / (2.0 * FD_H);
        assert_near(dX[e], fd, 1e-4 * fabs(fd) + 1e-6);
    }
    tcb_nn_free(index);
    free(xd);
    free(pd);
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
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_chamfer), cmocka_unit_test(test_confidence),
                                       cmocka_unit_test(test_edge_l1)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
