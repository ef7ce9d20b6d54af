/* The .npy reader: files numpy wrote (tests/data/npy, made by make.py
 * there) in every dtype, byte order, memory order and format version read
 * back exactly; hand-made bad headers refused with a message saying what is
 * wrong; every truncation and many byte changes of the real files handled
 * without a crash (a small deterministic fuzz under the sanitizers). */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "testutil.h"
#include "tcb/fsutil.h"
#include "tcb/npy.h"

#define DATA TCB_SOURCE_DIR "/tests/data/npy/"

static void load(const char *name, tcb_npy *a)
{
    tcb_error err = {0};
    if (tcb_npy_load(name, a, &err)) fail_msg("%s: %s", name, err.msg);
}

static void expect_msg(int rc, const tcb_error *err, const char *text)
{
    assert_int_equal(rc, TCB_ERR_INPUT);
    if (!strstr(err->msg, text)) fail_msg("'%s' does not say '%s'", err->msg, text);
}

/* ints[n] as the file's elements, through to_int64. */
static void expect_ints(const tcb_npy *a, const int64_t *want, size_t n)
{
    int64_t got[32];
    tcb_error err = {0};
    assert_int_equal(a->count, n);
    if (tcb_npy_to_int64(a, got, &err)) fail_msg("%s: %s", a->descr, err.msg);
    for (size_t k = 0; k < n; k++)
        if (got[k] != want[k]) fail_msg("%s[%zu] = %lld, expected %lld", a->descr, k, (long long)got[k], (long long)want[k]);
}

static void test_signed_integers(void **state)
{
    (void)state;
    static const struct { const char *file, *descr; int size; int64_t min, max; } cases[] = {
        {DATA "i1.npy", "|i1", 1, INT8_MIN, INT8_MAX},         {DATA "i2_le.npy", "<i2", 2, INT16_MIN, INT16_MAX},
        {DATA "i2_be.npy", ">i2", 2, INT16_MIN, INT16_MAX},    {DATA "i4_le.npy", "<i4", 4, INT32_MIN, INT32_MAX},
        {DATA "i4_be.npy", ">i4", 4, INT32_MIN, INT32_MAX},    {DATA "i8_le.npy", "<i8", 8, INT64_MIN, INT64_MAX},
        {DATA "i8_be.npy", ">i8", 8, INT64_MIN, INT64_MAX},
    };
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        tcb_npy a;
        load(cases[c].file, &a);
        assert_string_equal(a.descr, cases[c].descr);
        assert_int_equal(a.kind, 'i');
        assert_int_equal(a.item_size, cases[c].size);
        assert_int_equal(a.ndim, 1);
        assert_int_equal(a.shape[0], 5);
        assert_int_equal(a.major, 1);
        const int64_t want[5] = {0, 1, -1, cases[c].min, cases[c].max};
        expect_ints(&a, want, 5);
        double d[5];
        tcb_error err = {0};
        int rc = tcb_npy_to_double(&a, d, &err);
        if (cases[c].size == 8) { /* beyond 2^53: not exactly a double */
            expect_msg(rc, &err, "element 3 (dtype ");
        } else {
            assert_int_equal(rc, TCB_OK);
            for (int k = 0; k < 5; k++) assert_true(d[k] == (double)want[k]);
        }
        tcb_npy_free(&a);
    }
}

static void test_unsigned_integers_and_bool(void **state)
{
    (void)state;
    static const struct { const char *file; uint64_t max; } cases[] = {
        {DATA "u1.npy", UINT8_MAX},     {DATA "u2_le.npy", UINT16_MAX}, {DATA "u2_be.npy", UINT16_MAX},
        {DATA "u4_le.npy", UINT32_MAX}, {DATA "u4_be.npy", UINT32_MAX},
    };
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        tcb_npy a;
        load(cases[c].file, &a);
        assert_int_equal(a.kind, 'u');
        const int64_t want[5] = {0, 1, 2, (int64_t)cases[c].max - 1, (int64_t)cases[c].max};
        expect_ints(&a, want, 5);
        tcb_npy_free(&a);
    }
    /* u8: 2^64 - 2 and 2^64 - 1 are no int64 and no exact double. */
    for (int be = 0; be < 2; be++) {
        tcb_npy a;
        int64_t got[5];
        double d[5];
        tcb_error err = {0};
        load(be ? DATA "u8_be.npy" : DATA "u8_le.npy", &a);
        expect_msg(tcb_npy_to_int64(&a, got, &err), &err, "element 3: 18446744073709551614 is beyond the int64 range");
        expect_msg(tcb_npy_to_double(&a, d, &err), &err, "element 3 (dtype ");
        tcb_npy_free(&a);
    }
    tcb_npy a;
    load(DATA "b1.npy", &a);
    assert_string_equal(a.descr, "|b1");
    const int64_t want[3] = {1, 0, 1};
    expect_ints(&a, want, 3);
    tcb_npy_free(&a);
}

static int same_double(double a, double b) { return isnan(a) ? isnan(b) : a == b; }

static void test_floats(void **state)
{
    (void)state;
    static const struct { const char *file, *descr; double max, tiny; } cases[] = {
        {DATA "f4_le.npy", "<f4", FLT_MAX, FLT_TRUE_MIN}, {DATA "f4_be.npy", ">f4", FLT_MAX, FLT_TRUE_MIN},
        {DATA "f8_le.npy", "<f8", DBL_MAX, DBL_TRUE_MIN}, {DATA "f8_be.npy", ">f8", DBL_MAX, DBL_TRUE_MIN},
    };
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        tcb_npy a;
        load(cases[c].file, &a);
        assert_string_equal(a.descr, cases[c].descr);
        double d[6];
        tcb_error err = {0};
        assert_int_equal(tcb_npy_to_double(&a, d, &err), TCB_OK);
        const double want[6] = {0, -1.5, cases[c].max, cases[c].tiny, INFINITY, NAN};
        for (int k = 0; k < 6; k++)
            if (!same_double(d[k], want[k])) fail_msg("%s[%d] = %.17g, expected %.17g", cases[c].file, k, d[k], want[k]);
        int64_t ids[6];
        expect_msg(tcb_npy_to_int64(&a, ids, &err), &err, "expected integers, got floats");
        tcb_npy_free(&a);
    }
}

/* arange(12).reshape(4, 3) * 0.25 - 1 in C order, however stored. */
static void test_points_orders_and_versions(void **state)
{
    (void)state;
    static const struct { const char *file; int major, fortran; } cases[] = {
        {DATA "points_C_f8.npy", 1, 0}, {DATA "points_F_f8.npy", 1, 1}, {DATA "points_F_f4_be.npy", 1, 1},
        {DATA "points_v2.npy", 2, 0},   {DATA "points_v3.npy", 3, 0},
    };
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        tcb_npy a;
        load(cases[c].file, &a);
        assert_int_equal(a.major, cases[c].major);
        assert_int_equal(a.fortran_order, cases[c].fortran);
        char shape[32];
        tcb_npy_shape_text(&a, shape, sizeof shape);
        assert_string_equal(shape, "(4, 3)");
        double d[12];
        tcb_error err = {0};
        assert_int_equal(tcb_npy_to_double(&a, d, &err), TCB_OK);
        for (int k = 0; k < 12; k++)
            if (d[k] != k * 0.25 - 1) fail_msg("%s[%d] = %g, expected %g", cases[c].file, k, d[k], k * 0.25 - 1);
        tcb_npy_free(&a);
    }
    tcb_npy a;
    load(DATA "cube_F_i2.npy", &a);
    assert_int_equal(a.ndim, 3);
    assert_true(a.fortran_order && a.big_endian);
    int64_t want[24];
    for (int k = 0; k < 24; k++) want[k] = k - 12;
    expect_ints(&a, want, 24);
    tcb_npy_free(&a);
}

static void test_scalar_and_empty(void **state)
{
    (void)state;
    tcb_npy a;
    char shape[32];
    load(DATA "scalar_i8.npy", &a);
    assert_int_equal(a.ndim, 0);
    tcb_npy_shape_text(&a, shape, sizeof shape);
    assert_string_equal(shape, "()");
    const int64_t seven = 7;
    expect_ints(&a, &seven, 1);
    tcb_npy_free(&a);
    load(DATA "empty_i4.npy", &a);
    assert_int_equal(a.count, 0);
    tcb_npy_shape_text(&a, shape, sizeof shape);
    assert_string_equal(shape, "(0,)");
    tcb_npy_free(&a);
    load(DATA "empty_f8.npy", &a);
    assert_int_equal(a.count, 0);
    tcb_npy_shape_text(&a, shape, sizeof shape);
    assert_string_equal(shape, "(0, 3)");
    tcb_npy_free(&a);
}

/* A .npy image: magic, version major.0, the header's length, the header
 * text as given (no padding added) and n_data bytes of data. */
static size_t image(unsigned char *out, int major, const char *header, const void *data, size_t n_data)
{
    size_t h = strlen(header), at = 8;
    memcpy(out, "\x93NUMPY", 6);
    out[6] = (unsigned char)major, out[7] = 0;
    for (int k = 0; k < (major == 1 ? 2 : 4); k++) out[at++] = (unsigned char)(h >> (8 * k));
    memcpy(out + at, header, h);
    if (n_data) memcpy(out + at + h, data, n_data);
    return at + h + n_data;
}

static int parse_header(const char *header, size_t n_data, tcb_npy *a, tcb_error *err)
{
    static unsigned char buf[4096];
    static const unsigned char zeros[256];
    size_t n = image(buf, 1, header, zeros, n_data);
    return tcb_npy_parse(buf, n, a, err);
}

/* float16 (Occupancy Flow's point clouds) converts exactly, either byte
 * order: normal, subnormal, the largest, signed zero, infinity, NaN. */
static void test_half_floats(void **state)
{
    (void)state;
    static const uint16_t bits[] = {0x3c00, 0xc000, 0x0001, 0x03ff, 0x7bff, 0x3555, 0x8000, 0x7c00, 0xfc00, 0x7e00};
    const double want[] = {1.0, -2.0, ldexp(1, -24), ldexp(1023, -24), 65504.0, 0x1.554p-2, -0.0, INFINITY, -INFINITY, NAN};
    enum { N = sizeof bits / sizeof bits[0] };
    for (int big = 0; big <= 1; big++) {
        unsigned char data[2 * N], buf[512];
        for (int k = 0; k < N; k++)
            data[2 * k + big] = (unsigned char)(bits[k] & 0xff), data[2 * k + !big] = (unsigned char)(bits[k] >> 8);
        char header[128];
        snprintf(header, sizeof header, "{'descr': '%cf2', 'fortran_order': False, 'shape': (%d,)}", big ? '>' : '<', N);
        size_t n = image(buf, 1, header, data, sizeof data);
        tcb_npy a;
        tcb_error err = {0};
        assert_int_equal(tcb_npy_parse(buf, n, &a, &err), TCB_OK);
        assert_int_equal(a.item_size, 2);
        double got[N];
        assert_int_equal(tcb_npy_to_double(&a, got, &err), TCB_OK);
        for (int k = 0; k < N; k++) {
            if (!same_double(got[k], want[k]) || signbit(got[k]) != signbit(want[k]))
                fail_msg("%s half %04x: %a, expected %a", big ? "big-endian" : "little-endian", bits[k], got[k], want[k]);
        }
        int64_t ids[N];
        assert_int_not_equal(tcb_npy_to_int64(&a, ids, &err), TCB_OK); /* floats are not ids */
    }
}

static void test_bad_headers(void **state)
{
    (void)state;
    static const struct { const char *header; size_t n_data; const char *says; } cases[] = {
        {"", 0, "expected '{' (a Python dict), but the header ends"},
        {"[1]\n", 0, "expected '{' (a Python dict) at byte 0"},
        {"{'descr': '<f8', 'fortran_order': False}\n", 0, "no 'shape' key"},
        {"{'descr': '<f8', 'fortran_order': False, 'shape': (1,), 'extra': 1}\n", 8, "unexpected key 'extra'"},
        {"{'descr': '<f8', 'descr': '<f8', 'fortran_order': False, 'shape': ()}", 8, "'descr' given twice at byte 17"},
        {"{'descr': '<f8' 'fortran_order': False, 'shape': ()}", 8, "expected ',' or '}'"},
        {"{'descr' '<f8'}", 0, "expected ':' after 'descr'"},
        {"{'descr': '<f8', 'fortran_order': False, 'shape': (5)}", 40, "(5) is a number, not a tuple"},
        {"{'descr': '<f8', 'fortran_order': False, 'shape': (-5,)}", 0, "negative dimension"},
        {"{'descr': '<f8', 'fortran_order': False, 'shape': (05,)}", 0, "leading zero"},
        {"{'descr': '<f8', 'fortran_order': False, 'shape': (3L,)}", 0, "malformed integer"},
        {"{'descr': '<f8', 'fortran_order': False, 'shape': (1.5,)}", 0, "malformed integer"},
        {"{'descr': '<f8', 'fortran_order': False, 'shape': (3 4)}", 0, "expected ',' or ')'"},
        {"{'descr': '<f8', 'fortran_order': False, 'shape': (,)}", 0, "expected a non-negative integer"},
        {"{'descr': '<f8', 'fortran_order': False, 'shape': [3]}", 0, "expected a tuple such as (500, 3)"},
        {"{'descr': '<f8', 'fortran_order': False, 'shape': (99999999999999999999,)}", 0, "larger than 2^63 - 1"},
        {"{'descr': '<f8', 'fortran_order': False, 'shape': (4611686018427387904, 4611686018427387904)}", 0,
         "shape (4611686018427387904, 4611686018427387904) of <f8 is too large to address"},
        {"{'descr': '<u1', 'fortran_order': False, 'shape': (1,1,1,1,1,1,1,1,1,1,1,1,1,1,1,1,1,1,1,1,1,1,1,1,1,1,1,1,1,1,"
         "1,1,1)}", 1, "more than 32 dimensions"},
        {"{'descr': '<c16', 'fortran_order': False, 'shape': ()}", 16, "dtype '<c16' is not supported"},
        {"{'descr': '<f1', 'fortran_order': False, 'shape': ()}", 1, "dtype '<f1' is not supported"},
        {"{'descr': '|O', 'fortran_order': False, 'shape': ()}", 8, "dtype '|O' is not supported"},
        {"{'descr': '<b2', 'fortran_order': False, 'shape': ()}", 2, "dtype '<b2' is not supported"},
        {"{'descr': '|i4', 'fortran_order': False, 'shape': ()}", 4, "byte order '|' (not applicable) on a multi-byte"},
        {"{'descr': '=f8', 'fortran_order': False, 'shape': ()}", 8, "native byte order '='"},
        {"{'descr': 'f8', 'fortran_order': False, 'shape': ()}", 8, "dtype 'f8' is not supported"},
        {"{'descr': [('x', '<f8')], 'fortran_order': False, 'shape': ()}", 8, "structured dtypes"},
        {"{'descr': '<f8', 'fortran_order': true, 'shape': ()}", 8, "expected True or False"},
        {"{'descr': '<f8', 'fortran_order': 0, 'shape': ()}", 8, "expected True or False"},
        {"{'descr': '<f8", 0, "unterminated string"},
        {"{'descr': '<f\\x38', 'fortran_order': False, 'shape': ()}", 8, "escape sequence"},
        {"{'d\xc3\xa9scr': '<f8'}", 0, "byte 0xc3 in a string"},
        {"{descr: '<f8'}", 0, "expected a string as key"},
        {"{'descr': '<f8', 'fortran_order': False, 'shape': ()} x\n", 8, "text after the dict"},
        {"{'descr': '<f8', 'fortran_order': False, 'shape': (2, 3)}\n", 40, "truncated: shape (2, 3) of <f8 needs 48 bytes of data, the file has 40"},
        {"{'descr': '<f8', 'fortran_order': False, 'shape': (2,)}\n", 24, "bytes after the data: shape (2,) of <f8 needs 16"},
    };
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        tcb_npy a;
        tcb_error err = {0};
        int rc = parse_header(cases[c].header, cases[c].n_data, &a, &err);
        if (rc != TCB_ERR_INPUT || !strstr(err.msg, cases[c].says))
            fail_msg("header %s: rc %d, '%s', expected '%s'", cases[c].header, rc, err.msg, cases[c].says);
    }
}

/* What Python would also read: other quotes, no trailing comma, keys in
 * any order, whitespace and newlines between tokens, a big-endian
 * one-byte type. */
static void test_lenient_where_python_is(void **state)
{
    (void)state;
    tcb_npy a;
    tcb_error err = {0};
    assert_int_equal(parse_header("  {\"shape\" :(\n2 ,3 , ) ,\t'fortran_order':True,'descr':\"<i2\"}  \n", 12, &a, &err),
                     TCB_OK);
    assert_int_equal(a.ndim, 2);
    assert_true(a.fortran_order);
    assert_int_equal(a.count, 6);
    assert_int_equal(parse_header("{'descr': '>u1', 'fortran_order': False, 'shape': (3,)}", 3, &a, &err), TCB_OK);
    assert_false(a.big_endian);
}

static void test_prefix_errors(void **state)
{
    (void)state;
    unsigned char buf[256];
    tcb_npy a;
    tcb_error err = {0};
    const char *h = "{'descr': '<f8', 'fortran_order': False, 'shape': ()}\n";
    size_t n = image(buf, 1, h, "\0\0\0\0\0\0\0\0", 8);
    assert_int_equal(tcb_npy_parse(buf, n, &a, &err), TCB_OK);
    expect_msg(tcb_npy_parse("PK\3\4", 4, &a, &err), &err, "not a .npy file");
    expect_msg(tcb_npy_parse(buf, 7, &a, &err), &err, "not even the version");
    expect_msg(tcb_npy_parse(buf, 9, &a, &err), &err, "not even the header's length");
    expect_msg(tcb_npy_parse(buf, 30, &a, &err), &err, "truncated: the header says it has 54 bytes, the file has 20");
    buf[6] = 4;
    expect_msg(tcb_npy_parse(buf, n, &a, &err), &err, "format version 4.0 is not supported");
    buf[6] = 1, buf[7] = 1;
    expect_msg(tcb_npy_parse(buf, n, &a, &err), &err, "format version 1.1 is not supported");
    n = image(buf, 2, h, "\0\0\0\0\0\0\0\0", 8); /* 2.0: a 4-byte length */
    assert_int_equal(tcb_npy_parse(buf, n, &a, &err), TCB_OK);
    expect_msg(tcb_npy_parse(buf, 11, &a, &err), &err, "not even the header's length");
    n = image(buf, 1, "{'descr': '|b1', 'fortran_order': False, 'shape': (2,)}", "\1\2", 2);
    assert_int_equal(tcb_npy_parse(buf, n, &a, &err), TCB_OK);
    int64_t v[2];
    expect_msg(tcb_npy_to_int64(&a, v, &err), &err, "element 1: byte 2 is not a bool");
}

static void test_load_names_the_file(void **state)
{
    char path[TCB_PATH_MAX];
    tcb_npy a;
    tcb_error err = {0};
    static const char bad[] = "\x93NUMPY\x01\x00\x04\x00{'de";
    snprintf(path, sizeof path, "%s/bad.npy", (const char *)*state);
    assert_int_equal(tcb_write_file_atomic(path, bad, sizeof bad - 1, &err), TCB_OK);
    assert_int_equal(tcb_npy_load(path, &a, &err), TCB_ERR_INPUT);
    if (strncmp(err.msg, path, strlen(path)) || !strstr(err.msg, ": header: unterminated string"))
        fail_msg("%s", err.msg);
    snprintf(path, sizeof path, "%s/none.npy", (const char *)*state);
    assert_int_equal(tcb_npy_load(path, &a, &err), TCB_ERR_IO);
    assert_non_null(strstr(err.msg, "none.npy"));
}

/* Parses buf[0..n) and, when it parses, converts it both ways: any
 * outcome but a crash (the sanitizers watch) or a silent wrong size. */
static int parse_and_convert(const unsigned char *buf, size_t n)
{
    tcb_npy a;
    tcb_error err = {0};
    if (tcb_npy_parse(buf, n, &a, &err)) {
        assert_int_equal(err.code, TCB_ERR_INPUT);
        assert_true(err.msg[0] != '\0');
        return 0;
    }
    assert_true(a.count * (uint64_t)a.item_size <= n);
    int64_t *ids = malloc((a.count ? a.count : 1) * sizeof *ids);
    double *d = malloc((a.count ? a.count : 1) * sizeof *d);
    assert_true(ids && d);
    tcb_npy_to_int64(&a, ids, &err);
    tcb_npy_to_double(&a, d, &err);
    free(ids);
    free(d);
    return 1;
}

static void test_truncations_and_byte_changes(void **state)
{
    (void)state;
    static const char *files[] = {"points_F_f4_be.npy", "points_v3.npy", "cube_F_i2.npy", "u8_le.npy", "scalar_i8.npy"};
    static const unsigned char values[] = {0x00, 0xff, '(', ')', ',', '9', ' ', '\'', '}', 'F', '<', 0x80};
    for (size_t f = 0; f < sizeof files / sizeof files[0]; f++) {
        char path[TCB_PATH_MAX], *text;
        size_t len;
        tcb_error err = {0};
        snprintf(path, sizeof path, DATA "%s", files[f]);
        if (tcb_read_file(path, &text, &len, &err)) fail_msg("%s", err.msg);
        for (size_t n = 0; n < len; n++) { /* every truncation fails; a copy of n bytes, so ASan sees overreads */
            unsigned char *cut = malloc(n ? n : 1);
            assert_non_null(cut);
            memcpy(cut, text, n);
            assert_int_equal(parse_and_convert(cut, n), 0);
            free(cut);
        }
        unsigned char *buf = malloc(len);
        assert_non_null(buf);
        int parsed = 0;
        for (size_t at = 0; at < len && at < 128; at++)
            for (size_t v = 0; v < sizeof values; v++) {
                memcpy(buf, text, len);
                buf[at] = values[v];
                parsed += parse_and_convert(buf, len);
            }
        assert_true(parsed > 0); /* changes in the padding still parse */
        free(buf);
        free(text);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_signed_integers),
        cmocka_unit_test(test_unsigned_integers_and_bool),
        cmocka_unit_test(test_floats),
        cmocka_unit_test(test_half_floats),
        cmocka_unit_test(test_points_orders_and_versions),
        cmocka_unit_test(test_scalar_and_empty),
        cmocka_unit_test(test_bad_headers),
        cmocka_unit_test(test_lenient_where_python_is),
        cmocka_unit_test(test_prefix_errors),
        cmocka_unit_test_setup_teardown(test_load_names_the_file, tu_setup_tmpdir, tu_teardown_tmpdir),
        cmocka_unit_test(test_truncations_and_byte_changes),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
