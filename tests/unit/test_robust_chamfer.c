/* neural/robust_chamfer.c against a double reference written here
 * (brute-force nearest neighbours), its gradient by central differences of
 * that reference with the Welsch weights held at their values, as the
 * method detaches them. */
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

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_chamfer)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
