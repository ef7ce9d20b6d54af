/* What tcb_surface_check (scoring/surface_check.c) accepts of a method's
 * surface: a mesh parametrised by charts (uv and chart both given) or one
 * without (n_charts 0, both NULL; neupig's template), never half of a
 * parametrisation; and that a mesh without charts has no collapsed patches
 * (views/frames_collapse.c). */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>

#include "views/frames_style.h"
#include "scoring/scoring.h"

/* A tetrahedron, its four vertices in one chart at the corners of (u, v). */
static float verts[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
static float uv[] = {0, 0, 1, 0, 0, 1, 1, 1};
static int32_t chart[] = {0, 0, 0, 0};
static int32_t faces[] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};

static int check(int n_charts, float *u, int32_t *c)
{
    tcb_uv_mesh m = {4, 4, n_charts, verts, u, c, faces};
    tcb_error err = {0};
    return tcb_surface_check(&m, 7, 4, &err);
}

static void test_with_and_without_charts(void **state)
{
    (void)state;
    assert_int_equal(check(1, uv, chart), TCB_OK);
    assert_int_equal(check(0, NULL, NULL), TCB_OK);
}

static void test_half_a_parametrisation(void **state)
{
    (void)state;
    assert_int_equal(check(0, uv, chart), TCB_ERR_INTERNAL);
    assert_int_equal(check(0, uv, NULL), TCB_ERR_INTERNAL);
    assert_int_equal(check(1, NULL, chart), TCB_ERR_INTERNAL);
    assert_int_equal(check(1, uv, NULL), TCB_ERR_INTERNAL);
    assert_int_equal(check(5, uv, chart), TCB_ERR_INTERNAL); /* over max_charts */
}

static void test_chartless_faces_checked(void **state)
{
    (void)state;
    faces[4] = 4;
    int rc = check(0, NULL, NULL);
    faces[4] = 1;
    assert_int_equal(rc, TCB_ERR_INTERNAL);
    verts[3] = INFINITY;
    rc = check(0, NULL, NULL);
    verts[3] = 1;
    assert_int_equal(rc, TCB_ERR_NUMERIC);
}

static void test_chartless_never_collapsed(void **state)
{
    (void)state;
    tcb_uv_mesh m = {4, 4, 0, verts, NULL, NULL, faces};
    tcb_error err = {0};
    unsigned char flags[1];
    int n = -1;
    assert_int_equal(tcb_frames_collapsed(&m, 100.0, flags, &n, &err), TCB_OK);
    assert_int_equal(n, 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_with_and_without_charts),
        cmocka_unit_test(test_half_a_parametrisation),
        cmocka_unit_test(test_chartless_faces_checked),
        cmocka_unit_test(test_chartless_never_collapsed),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
