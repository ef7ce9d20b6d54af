/* methods/pcgrid/prepare.c: the normalisation into the grids' cube, and
 * the keyframe (most occupied cells, weighted towards the middle) on cases
 * worked out by hand. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>

#include "methods/pcgrid/prepare.h"
#include "testutil.h"

static void test_map(void **state)
{
    (void)state;
    const float a[] = {1, 2, 3, 5, 2, 4}, b[] = {3, -2, 3.5f};
    const float *pts[] = {a, b};
    const int n[] = {2, 1};
    tcb_pcgrid_frame_map m;
    tcb_error err = {0};
    assert_int_equal(tcb_pcgrid_frame_map_of(pts, n, 2, &m, &err), TCB_OK);
    /* Box x [1, 5], y [−2, 2], z [3, 4]: centre (3, 0, 3.5), half side 2. */
    assert_near(m.centre[0], 3.0, 1e-12);
    assert_near(m.centre[1], 0.0, 1e-12);
    assert_near(m.centre[2], 3.5, 1e-12);
    assert_near(m.scale, 0.95 / 2.0, 1e-12);
    float out[6];
    tcb_pcgrid_map_points(&m, a, 2, out);
    assert_near(out[0], -0.95, 1e-6);
    assert_near(out[3], 0.95, 1e-6);
    assert_near(out[1], 0.95, 1e-6);
    const float same[] = {1, 1, 1, 1, 1, 1};
    const float *one[] = {same};
    const int two[] = {2};
    assert_int_equal(tcb_pcgrid_frame_map_of(one, two, 1, &m, &err), TCB_ERR_INPUT);
    const float bad[] = {0, NAN, 0};
    const float *nan_pts[] = {bad};
    const int one_n[] = {1};
    assert_int_equal(tcb_pcgrid_frame_map_of(nan_pts, one_n, 1, &m, &err), TCB_ERR_NUMERIC);
}

/* Frames of 8 points: all in one cell, or spread over 8 cells. */
static void test_keyframe(void **state)
{
    (void)state;
    float clump[24], spread[24];
    for (int i = 0; i < 8; i++)
        for (int k = 0; k < 3; k++) {
            clump[3 * i + k] = 0.1f + 0.0001f * (float)i;
            spread[3 * i + k] = ((i >> k) & 1) ? 0.5f : -0.5f;
        }
    const int n[] = {8, 8, 8, 8, 8};
    const float *one_spread[] = {clump, clump, clump, spread, clump};
    int key = -1;
    tcb_error err = {0};
    assert_int_equal(tcb_pcgrid_keyframe(one_spread, n, 4, 64, &key, &err), TCB_OK);
    assert_int_equal(key, 3);
    /* Equal occupancy: the weight exp(−0.001 k²) decides, k = t + ⌊−T/2⌋:
     * T = 5 gives k = −3 … 1, so t = 3; T = 4 gives k = −2 … 1, so t = 2. */
    const float *all_clump[] = {clump, clump, clump, clump, clump};
    assert_int_equal(tcb_pcgrid_keyframe(all_clump, n, 5, 64, &key, &err), TCB_OK);
    assert_int_equal(key, 3);
    assert_int_equal(tcb_pcgrid_keyframe(all_clump, n, 4, 64, &key, &err), TCB_OK);
    assert_int_equal(key, 2);
    /* 8 cells far from the middle still beat 1 cell in it: 8·e^(−0.009) > 1. */
    const float *early[] = {spread, clump, clump, clump, clump, clump, clump};
    const int n7[] = {8, 8, 8, 8, 8, 8, 8};
    assert_int_equal(tcb_pcgrid_keyframe(early, n7, 7, 64, &key, &err), TCB_OK);
    assert_int_equal(key, 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_map), cmocka_unit_test(test_keyframe)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
