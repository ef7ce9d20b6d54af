/* The .npy writer: the arrays of tests/data/npy that numpy wrote as
 * version 1.0, little-endian C-order files (integers, floats with their
 * extremes, infinities and NaN, 2-D points, a scalar, an empty array) come
 * out byte for byte as numpy wrote them; a 3-D array larger than the
 * writer's chunk reads back exactly; a path that cannot be written is an
 * error naming it, with nothing left behind. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <dirent.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "testutil.h"
#include "tcb/fsutil.h"
#include "tcb/npy.h"

#define DATA TCB_SOURCE_DIR "/tests/data/npy/"

/* Writes the array to dir/name and compares it with numpy's file `name`. */
static void expect_as_numpy(const char *dir, const char *name, tcb_npy_dtype dtype, int ndim,
                            const uint64_t *shape, const void *data)
{
    char mine[TCB_PATH_MAX], theirs[TCB_PATH_MAX];
    snprintf(mine, sizeof mine, "%s/%s", dir, name);
    snprintf(theirs, sizeof theirs, DATA "%s", name);
    tcb_error err = {0};
    if (tcb_npy_save(mine, dtype, ndim, shape, data, &err)) fail_msg("%s: %s", name, err.msg);
    char *a, *b;
    size_t na, nb;
    if (tcb_read_file(mine, &a, &na, &err) || tcb_read_file(theirs, &b, &nb, &err)) fail_msg("%s", err.msg);
    if (na != nb || memcmp(a, b, na)) fail_msg("%s: %zu bytes differ from numpy's %zu", name, na, nb);
    free(a);
    free(b);
}

static void test_same_bytes_as_numpy(void **state)
{
    const char *dir = *state;
    const int32_t i4[] = {0, 1, -1, INT32_MIN, INT32_MAX};
    const int64_t i8[] = {0, 1, -1, INT64_MIN, INT64_MAX};
    const float f4[] = {0, -1.5f, FLT_MAX, FLT_TRUE_MIN, INFINITY, NAN};
    const double f8[] = {0, -1.5, DBL_MAX, DBL_TRUE_MIN, INFINITY, NAN};
    double points[12];
    for (int k = 0; k < 12; k++) points[k] = k * 0.25 - 1;
    const int64_t scalar = 7;
    const uint64_t five = 5, six = 6, p43[] = {4, 3}, e03[] = {0, 3};
    expect_as_numpy(dir, "i4_le.npy", TCB_NPY_I4, 1, &five, i4);
    expect_as_numpy(dir, "i8_le.npy", TCB_NPY_I8, 1, &five, i8);
    expect_as_numpy(dir, "f4_le.npy", TCB_NPY_F4, 1, &six, f4);
    expect_as_numpy(dir, "f8_le.npy", TCB_NPY_F8, 1, &six, f8);
    expect_as_numpy(dir, "points_C_f8.npy", TCB_NPY_F8, 2, p43, points);
    expect_as_numpy(dir, "scalar_i8.npy", TCB_NPY_I8, 0, NULL, &scalar);
    expect_as_numpy(dir, "empty_f8.npy", TCB_NPY_F8, 2, e03, points);
}

static void test_large_3d_round_trip(void **state)
{
    const uint64_t shape[] = {7, 3001, 3}; /* 252 084 bytes: several chunks, the last one partial */
    size_t n = 7 * 3001 * 3;
    float *x = tu_falloc(n);
    for (size_t k = 0; k < n; k++) x[k] = (float)k * 0.5f - 1000.0f;
    char path[TCB_PATH_MAX];
    snprintf(path, sizeof path, "%s/frames.npy", (const char *)*state);
    tcb_error err = {0};
    if (tcb_npy_save(path, TCB_NPY_F4, 3, shape, x, &err)) fail_msg("%s", err.msg);
    tcb_npy a;
    if (tcb_npy_load(path, &a, &err)) fail_msg("%s", err.msg);
    assert_string_equal(a.descr, "<f4");
    assert_int_equal(a.ndim, 3);
    for (int d = 0; d < 3; d++) assert_int_equal(a.shape[d], shape[d]);
    assert_int_equal((uintptr_t)(a.data - (const unsigned char *)a.owned) % 64, 0);
    double *back = tu_dalloc(n);
    if (tcb_npy_to_double(&a, back, &err)) fail_msg("%s", err.msg);
    for (size_t k = 0; k < n; k++)
        if (back[k] != x[k]) fail_msg("element %zu: %g, wrote %g", k, back[k], (double)x[k]);
    tcb_npy_free(&a);
    free(back);
    free(x);
}

static void test_unwritable_path(void **state)
{
    const char *dir = *state;
    char blocker[TCB_PATH_MAX], path[TCB_PATH_MAX + 16];
    tu_write_text(dir, "file", "x", blocker, sizeof blocker);
    snprintf(path, sizeof path, "%s/sub/a.npy", blocker); /* a directory below a file */
    const int32_t one = 1;
    const uint64_t shape = 1;
    tcb_error err = {0};
    assert_int_not_equal(tcb_npy_save(path, TCB_NPY_I4, 1, &shape, &one, &err), TCB_OK);
    if (!strstr(err.msg, blocker)) fail_msg("'%s' does not name %s", err.msg, blocker);
    DIR *d = opendir(dir);
    int entries = 0;
    for (struct dirent *e; (e = readdir(d));) entries += e->d_name[0] != '.';
    closedir(d);
    assert_int_equal(entries, 1); /* only the blocking file: no temporary left */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_same_bytes_as_numpy, tu_setup_tmpdir, tu_teardown_tmpdir),
        cmocka_unit_test_setup_teardown(test_large_3d_round_trip, tu_setup_tmpdir, tu_teardown_tmpdir),
        cmocka_unit_test_setup_teardown(test_unwritable_path, tu_setup_tmpdir, tu_teardown_tmpdir),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
