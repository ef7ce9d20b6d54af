/* The reconstruction metrics (tcb/metrics.h, TCB_RECON_*): hand-computed
 * cases, identical sample sets, the F-score without any match, the face
 * normals of the samples and bad input. numpy/scipy (cKDTree) recompute
 * them on 100 000-sample meshes in tests/integration/test_surface_metrics.sh. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>

#include "tcb/geometry.h"
#include "tcb/metrics.h"

static void check_close(double got, double want, double tol, const char *what)
{
    if (!(fabs(got - want) <= tol)) fail_msg("%s: got %.17g, want %.17g", what, got, want);
}

/* One predicted sample at the origin; GT samples 0.003 and 0.02 away on x:
 *   acc  = [0.003]            → P = 1 at both thresholds
 *   comp = [0.003, 0.02]      → R = 1/2 at both (0.02 > 0.01)
 *   CD-L2 = 0.5 (0.003² + (0.003² + 0.02²) / 2)
 *   F = 2 · 1 · 0.5 / 1.5 = 2/3
 *   NC: the predicted normal +z; GT normals −z (matched both ways) and +x
 *   (its nearest prediction is +z: |cos| 0) → 0.5 (1 + (1 + 0) / 2) = 0.75 */
static void test_hand_computed(void **state)
{
    (void)state;
    const float pred[] = {0, 0, 0}, pred_n[] = {0, 0, 1};
    const float gt[] = {0.003f, 0, 0, 0.02f, 0, 0}, gt_n[] = {0, 0, -1, 1, 0, 0};
    double v[TCB_N_RECON];
    tcb_error err = {0};
    assert_int_equal(tcb_recon_metrics(pred, pred_n, 1, gt, gt_n, 2, v, &err), TCB_OK);
    double a = (double)0.003f, b = (double)0.02f;
    check_close(v[TCB_RECON_CDL2], 0.5 * (a * a + (a * a + b * b) / 2), 1e-18, "cdl2");
    check_close(v[TCB_RECON_NC], 0.75, 1e-15, "nc");
    check_close(v[TCB_RECON_FSCORE05], 2.0 / 3.0, 1e-15, "fscore05");
    check_close(v[TCB_RECON_FSCORE1], 2.0 / 3.0, 1e-15, "fscore1");
}

/* 0.005 < d ≤ 0.01: counted at 1 %, not at 0.5 %; nothing within either: 0. */
static void test_thresholds(void **state)
{
    (void)state;
    const float p[] = {0, 0, 0}, n[] = {0, 0, 1};
    const float near[] = {0.008f, 0, 0}, far[] = {0.5f, 0, 0};
    double v[TCB_N_RECON];
    assert_int_equal(tcb_recon_metrics(p, n, 1, near, n, 1, v, NULL), TCB_OK);
    assert_true(v[TCB_RECON_FSCORE05] == 0 && v[TCB_RECON_FSCORE1] == 1);
    assert_int_equal(tcb_recon_metrics(p, n, 1, far, n, 1, v, NULL), TCB_OK);
    assert_true(v[TCB_RECON_FSCORE05] == 0 && v[TCB_RECON_FSCORE1] == 0);
    check_close(v[TCB_RECON_CDL2], (double)0.5f * 0.5f, 1e-15, "cdl2 far");
}

/* A two-triangle mesh sampled twice from the same stream: the same points,
 * so CD-L2 0, NC 1 and F-score 1; each sample lies on one of the faces with
 * that face's unit normal. */
static void test_identical_meshes(void **state)
{
    (void)state;
    const float verts[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    const int32_t faces[] = {0, 1, 2, 0, 3, 1};
    enum { N = 500 };
    float a[3 * N], an[3 * N], b[3 * N], bn[3 * N];
    tcb_rng r1, r2;
    tcb_rng_seed(&r1, 5), tcb_rng_seed(&r2, 5);
    assert_int_equal(tcb_recon_sample(verts, faces, 2, N, &r1, a, an, NULL), TCB_OK);
    assert_int_equal(tcb_recon_sample(verts, faces, 2, N, &r2, b, bn, NULL), TCB_OK);
    int on_z = 0;
    for (int s = 0; s < N; s++) {
        /* face 0 is the z = 0 triangle (normal +z), face 1 the y = 0 one (+y) */
        int z0 = an[3 * s + 2] == 1.0f && an[3 * s] == 0 && an[3 * s + 1] == 0;
        int y0 = an[3 * s + 1] == 1.0f && an[3 * s] == 0 && an[3 * s + 2] == 0;
        assert_true(z0 != y0);
        assert_true(z0 ? a[3 * s + 2] == 0 : a[3 * s + 1] == 0);
        on_z += z0;
    }
    assert_true(on_z > 200 && on_z < 300); /* equal areas: about half each */
    double v[TCB_N_RECON];
    assert_int_equal(tcb_recon_metrics(a, an, N, b, bn, N, v, NULL), TCB_OK);
    assert_true(v[TCB_RECON_CDL2] == 0);
    check_close(v[TCB_RECON_NC], 1, 1e-7, "nc");
    assert_true(v[TCB_RECON_FSCORE05] == 1 && v[TCB_RECON_FSCORE1] == 1);
}

static void test_errors(void **state)
{
    (void)state;
    const float p[] = {0, 0, 0}, n[] = {0, 0, 1}, bad[] = {NAN, 0, 0};
    double v[TCB_N_RECON];
    tcb_error err = {0};
    assert_int_equal(tcb_recon_metrics(p, n, 0, p, n, 1, v, &err), TCB_ERR_INPUT);
    assert_int_equal(tcb_recon_metrics(bad, n, 1, p, n, 1, v, &err), TCB_ERR_NUMERIC);
    /* a mesh of no area cannot be sampled */
    const float flat[] = {0, 0, 0, 1, 0, 0, 2, 0, 0};
    const int32_t f[] = {0, 1, 2};
    float out[3], out_n[3];
    tcb_rng r;
    tcb_rng_seed(&r, 1);
    assert_int_equal(tcb_recon_sample(flat, f, 1, 1, &r, out, out_n, &err), TCB_ERR_INPUT);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_hand_computed),
        cmocka_unit_test(test_thresholds),
        cmocka_unit_test(test_identical_meshes),
        cmocka_unit_test(test_errors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
