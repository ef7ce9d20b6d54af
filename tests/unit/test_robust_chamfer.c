/* neural/robust_chamfer.c against a double reference written here
 * (brute-force nearest neighbours), its gradient by central differences of
 * that reference with the Welsch weights held at their values, as the
 * method detaches them; the normal term beside it likewise. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>

#include "neural/robust_chamfer.h"
#include "tcb/rng.h"
#include "testutil.h"

#define FD_H 1e-6
enum { NX = 30, NP = 40 };

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
    assert_int_equal(tcb_robust_chamfer(X, NX, P, NP, index, 0.3, &cd, dX, &err), TCB_OK);
    double *xd = tu_to_double(X, 3 * NX), *pd = tu_to_double(P, 3 * NP), wx[NX], wp[NP];
    double ref = tu_ref_chamfer_way(xd, NX, pd, NP, NULL, wx) + tu_ref_chamfer_way(pd, NP, xd, NX, NULL, wp);
    assert_near(cd, ref, 1e-6 * ref);
    for (int e = 0; e < 3 * NX; e++) {
        double keep = xd[e], l[2];
        for (int s = 0; s < 2; s++) {
            xd[e] = keep + (s ? -FD_H : FD_H);
            l[s] = tu_ref_chamfer_way(xd, NX, pd, NP, wx, NULL) + tu_ref_chamfer_way(pd, NP, xd, NX, wp, NULL);
        }
        xd[e] = keep;
        double fd = (l[0] - l[1]) / (2.0 * FD_H);
        assert_near(dX[e], fd, 1e-4 * fabs(fd) + 1e-6);
    }
    tcb_nn_free(index);
    free(xd);
    free(pd);
}

static int nearest(const double *q, const double *pts, int n)
{
    int arg = 0;
    double best = INFINITY;
    for (int i = 0; i < n; i++) {
        double s = 0;
        for (int k = 0; k < 3; k++) s += (q[k] - pts[3 * i + k]) * (q[k] - pts[3 * i + k]);
        if (s < best) best = s, arg = i;
    }
    return arg;
}

static double abs_cos_gap(const double *a, const double *b)
{
    double ab = 0, aa = 0, bb = 0;
    for (int k = 0; k < 3; k++) ab += a[k] * b[k], aa += a[k] * a[k], bb += b[k] * b[k];
    return 1 - fabs(ab / sqrt(aa * bb));
}

/* the normal term as it reads: means of 1 − |cos| over each side's nearest */
static double ref_normal(const double *x, const double *nx, const double *p, const double *np)
{
    double s = 0;
    for (int i = 0; i < NX; i++) s += abs_cos_gap(nx + 3 * i, np + 3 * nearest(x + 3 * i, p, NP)) / NX;
    for (int j = 0; j < NP; j++) s += abs_cos_gap(np + 3 * j, nx + 3 * nearest(p + 3 * j, x, NX)) / NP;
    return s;
}

/* The normal term against the definition, and its gradient in the moved
 * side's normals (not unit: the normalisation is part of it) by central
 * differences; the Chamfer beside it unchanged. */
static void test_normals(void **state)
{
    (void)state;
    tcb_rng rng;
    tcb_rng_seed(&rng, 31);
    float X[3 * NX], P[3 * NP], NXs[3 * NX], NPs[3 * NP], dX[3 * NX], dNX[3 * NX], dX0[3 * NX];
    tu_fill_uniform(&rng, X, 3 * NX, -0.5, 0.5);
    tu_fill_uniform(&rng, P, 3 * NP, -0.6, 0.6);
    tu_fill_uniform(&rng, NXs, 3 * NX, -1, 1);
    tu_fill_uniform(&rng, NPs, 3 * NP, -1, 1);
    tcb_nn *index;
    tcb_error err = {0};
    assert_int_equal(tcb_nn_build(P, NP, &index, &err), TCB_OK);
    double cd, cd0, normal;
    assert_int_equal(tcb_robust_chamfer_normals(X, NXs, NX, P, NPs, NP, index, 0.3, &cd, &normal, dX, dNX, &err),
                     TCB_OK);
    assert_int_equal(tcb_robust_chamfer(X, NX, P, NP, index, 0.3, &cd0, dX0, &err), TCB_OK);
    assert_near(cd, cd0, 0);
    for (int e = 0; e < 3 * NX; e++) assert_near(dX[e], dX0[e], 0);
    double *xd = tu_to_double(X, 3 * NX), *pd = tu_to_double(P, 3 * NP);
    double *nxd = tu_to_double(NXs, 3 * NX), *npd = tu_to_double(NPs, 3 * NP);
    assert_near(normal, ref_normal(xd, nxd, pd, npd), 1e-6);
    for (int e = 0; e < 3 * NX; e++) {
        double keep = nxd[e], l[2];
        for (int s = 0; s < 2; s++) {
            nxd[e] = keep + (s ? -FD_H : FD_H);
            l[s] = ref_normal(xd, nxd, pd, npd);
        }
        nxd[e] = keep;
        double fd = (l[0] - l[1]) / (2.0 * FD_H);
        assert_near(dNX[e], fd, 1e-4 * fabs(fd) + 1e-6);
    }
    tcb_nn_free(index);
    free(xd), free(pd), free(nxd), free(npd);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_chamfer), cmocka_unit_test(test_normals)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
