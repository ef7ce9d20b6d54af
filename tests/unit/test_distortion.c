/* tcb_sequence_distortion on a unit square (two triangles) whose frames
 * are worked out by hand: a uniform scale, a rigid motion, a stretch. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "tcb/distortion.h"

#define TOL 1e-12

static const float square[4][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};

/* Frame 0 the square; 1 scaled by 2; 2 turned 90° about z and moved;
 * 3 stretched by 1.5 along x. */
static void make(tcb_sequence *s)
{
    tcb_error err = {0};
    assert_int_equal(tcb_sequence_alloc(s, "square", 4, 4, 2, &err), TCB_OK);
    const int32_t faces[6] = {0, 1, 2, 0, 2, 3};
    memcpy(s->faces, faces, sizeof faces);
    for (int v = 0; v < 4; v++) {
        const float *p = square[v];
        float *f0 = s->verts + 3 * v, *f1 = f0 + 12, *f2 = f1 + 12, *f3 = f2 + 12;
        memcpy(f0, p, 3 * sizeof *p);
        for (int k = 0; k < 3; k++) f1[k] = 2.0f * p[k];
        f2[0] = -p[1] + 5.0f, f2[1] = p[0] - 2.0f, f2[2] = p[2] + 1.0f;
        f3[0] = 1.5f * p[0], f3[1] = p[1], f3[2] = p[2];
    }
}

static void test_square(void **state)
{
    (void)state;
    tcb_sequence s;
    make(&s);
    tcb_distortion d[4];
    tcb_error err = {0};
    assert_int_equal(tcb_sequence_distortion(&s, d, &err), TCB_OK);
    assert_true(d[0].edge_mean == 0.0 && d[0].edge_max == 0.0 && d[0].geo_mean == 0.0);
    assert_true(fabs(d[0].area_ratio - 1.0) < TOL);
    /* Every length doubles, the area quadruples. */
    assert_true(fabs(d[1].edge_mean - 1.0) < TOL && fabs(d[1].edge_max - 1.0) < TOL);
    assert_true(fabs(d[1].geo_mean - 1.0) < TOL && fabs(d[1].area_ratio - 4.0) < TOL);
    /* A rigid motion changes nothing. */
    assert_true(d[2].edge_max < 1e-6 && d[2].geo_mean < 1e-6 && fabs(d[2].area_ratio - 1.0) < 1e-6);
    /* Stretch: the two x edges +50 %, the diagonal √3.25/√2 − 1, the y edges
     * unchanged; geodesics from each corner: the x neighbour +50 %, the
     * diagonal as the edge, the y neighbour 0, the two-edge paths 2 → 2.5. */
    double diag = sqrt(3.25) / sqrt(2.0) - 1.0;
    assert_true(fabs(d[3].edge_mean - (0.5 + 0.5 + diag) / 5.0) < TOL);
    assert_true(fabs(d[3].edge_max - 0.5) < TOL);
    assert_true(fabs(d[3].geo_mean - (4 * 0.5 + 2 * diag + 2 * 0.25) / 12.0) < TOL);
    assert_true(fabs(d[3].area_ratio - 1.5) < TOL);
    tcb_sequence_free(&s);
}

static void test_bad_faces(void **state)
{
    (void)state;
    tcb_sequence s;
    make(&s);
    s.faces[5] = 7;
    tcb_distortion d[4];
    tcb_error err = {0};
    assert_int_equal(tcb_sequence_distortion(&s, d, &err), TCB_ERR_INPUT);
    tcb_sequence_free(&s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_square), cmocka_unit_test(test_bad_faces)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
