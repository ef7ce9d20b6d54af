/* The checkerboard texture of `tcbench frames` (views/checker.c): the
 * layout of charts in the image, texture coordinates inside their chart's
 * cell, the two tones and the white origin check, and the PNG holding what
 * tcb_checker_color says, read back with cairo. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <cairo.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "views/checker.h"
#include "testutil.h"

static void test_layout(void **state)
{
    (void)state;
    tcb_checker c = tcb_checker_layout(10);
    assert_int_equal(c.cols, 4);
    assert_int_equal(c.rows, 3);
    c = tcb_checker_layout(4);
    assert_int_equal(c.cols, 2);
    assert_int_equal(c.rows, 2);
    c = tcb_checker_layout(1);
    assert_int_equal(c.cols * c.rows, 1);
}

/* Chart p's square lands inside cell p (column p % cols, row p / cols from
 * the top, i.e. from v = 1 down), clear of the gutter. */
static void test_texcoord_in_cell(void **state)
{
    (void)state;
    tcb_checker c = tcb_checker_layout(10);
    const double g = (double)TCB_CHECKER_GUTTER / TCB_CHECKER_CELL;
    for (int p = 0; p < 10; p++)
        for (int corner = 0; corner < 4; corner++) {
            float vt[2];
            tcb_checker_texcoord(&c, p, corner & 1, corner >> 1, vt);
            double x = vt[0] * c.cols - p % c.cols, y = (1 - vt[1]) * c.rows - p / c.cols;
            assert_true(x >= g - 1e-6 && x <= 1 - g + 1e-6);
            assert_true(y >= g - 1e-6 && y <= 1 - g + 1e-6);
            /* u grows to the right, v upwards */
            assert_near(x, (corner & 1) ? 1 - g : g, 1e-6);
            assert_near(y, (corner >> 1) ? g : 1 - g, 1e-6);
        }
}

static int same(const uint8_t *a, const uint8_t *b) { return a[0] == b[0] && a[1] == b[1] && a[2] == b[2]; }

static void test_tones(void **state)
{
    (void)state;
    tcb_checker c = tcb_checker_layout(3);
    const double h = 0.5 / TCB_CHECKER_CHECKS; /* half a check */
    uint8_t o[3], a[3], b[3], d[3], other[3];
    tcb_checker_color(&c, 1, h, h, o);
    assert_true(o[0] == 250 && o[1] == 250 && o[2] == 250); /* the origin check */
    tcb_checker_color(&c, 1, 3 * h, h, a);          /* check (1, 0) */
    tcb_checker_color(&c, 1, 3 * h, 3 * h, b);      /* check (1, 1) */
    tcb_checker_color(&c, 1, 7 * h, h, d);          /* check (3, 0): a's tone */
    assert_false(same(a, b));
    assert_true(same(a, d));
    tcb_checker_color(&c, 2, 3 * h, h, other);
    assert_false(same(a, other)); /* charts told apart */
}

static void test_png(void **state)
{
    (void)state;
    char path[] = "/tmp/tcb_test_checker_XXXXXX";
    int fd = mkstemp(path);
    assert_true(fd >= 0);
    close(fd);
    tcb_checker c = tcb_checker_layout(5);
    tcb_error err = {0};
    assert_int_equal(tcb_checker_write_png(&c, path, &err), TCB_OK);
    cairo_surface_t *s = cairo_image_surface_create_from_png(path);
    assert_int_equal(cairo_surface_status(s), CAIRO_STATUS_SUCCESS);
    assert_int_equal(cairo_image_surface_get_width(s), 3 * TCB_CHECKER_CELL);
    assert_int_equal(cairo_image_surface_get_height(s), 2 * TCB_CHECKER_CELL);
    const unsigned char *data = cairo_image_surface_get_data(s);
    int stride = cairo_image_surface_get_stride(s);
    /* the middle of chart 4's check (5, 2): column 1, row 1 of the grid */
    double u = 5.5 / TCB_CHECKER_CHECKS, v = 2.5 / TCB_CHECKER_CHECKS;
    float vt[2];
    tcb_checker_texcoord(&c, 4, u, v, vt);
    int x = (int)(vt[0] * 3 * TCB_CHECKER_CELL), y = (int)((1 - vt[1]) * 2 * TCB_CHECKER_CELL);
    uint32_t px;
    memcpy(&px, data + (size_t)y * stride + 4 * (size_t)x, 4);
    uint8_t want[3], got[3] = {(uint8_t)(px >> 16), (uint8_t)(px >> 8), (uint8_t)px};
    tcb_checker_color(&c, 4, u, v, want);
    assert_true(same(got, want));
    cairo_surface_destroy(s);
    unlink(path);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_layout),
        cmocka_unit_test(test_texcoord_in_cell),
        cmocka_unit_test(test_tones),
        cmocka_unit_test(test_png),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
