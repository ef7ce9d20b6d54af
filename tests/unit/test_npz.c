/* The .npz reader: archives numpy and zipfile wrote (tests/data/npz, made
 * by make.py there) stored, deflated and with ZIP64 fields, read back
 * exactly; every truncation and many byte changes of them handled without
 * a crash, an error naming the file (a small deterministic fuzz under the
 * sanitizers; fuzz/targets/npz.c searches further). */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tcb/fsutil.h"
#include "tcb/npz.h"

#define DATA TCB_SOURCE_DIR "/tests/data/npz/"

static const char *const archives[] = {DATA "stored.npz", DATA "deflated.npz", DATA "zip64.npz"};

/* Member name of z as an array of n int64 / double values. */
static void expect_member(const tcb_npz *z, const char *name, const double *want, int n)
{
    int k = tcb_npz_find(z, name);
    if (k < 0) fail_msg("%s: no member %s", z->path, name);
    tcb_npy a;
    tcb_error err = {0};
    if (tcb_npz_read(z, k, &a, &err)) fail_msg("%s", err.msg);
    double got[12];
    assert_int_equal(a.count, n);
    if (tcb_npy_to_double(&a, got, &err)) fail_msg("%s", err.msg);
    for (int i = 0; i < n; i++)
        if (got[i] != want[i]) fail_msg("%s: %s[%d] = %g, expected %g", z->path, name, i, got[i], want[i]);
    tcb_npy_free(&a);
}

static void test_read(void **state)
{
    (void)state;
    static const double ids[4] = {0, 1, 2, 3}, back[4] = {3, 2, 1, 0};
    double points[12];
    for (int i = 0; i < 12; i++) points[i] = i / 4.0;
    for (size_t f = 0; f < sizeof archives / sizeof archives[0]; f++) {
        tcb_npz z;
        tcb_error err = {0};
        if (tcb_npz_open(archives[f], &z, &err)) fail_msg("%s", err.msg);
        assert_int_equal(z.n, 3);
        expect_member(&z, "0.npy", ids, 4);
        expect_member(&z, "1.npy", points, 12);
        expect_member(&z, "2.npy", back, 4);
        assert_int_equal(tcb_npz_find(&z, "3.npy"), -1);
        assert_int_equal(z.members[1].method, f == 0 ? 0 : 8);
        tcb_npz_close(&z);
    }
}

/* Opens path and reads every member; an error must name the file. */
static void read_all(const char *path)
{
    tcb_npz z;
    tcb_error err = {0};
    if (tcb_npz_open(path, &z, &err)) {
        if (!strstr(err.msg, path)) fail_msg("'%s' does not name %s", err.msg, path);
        return;
    }
    for (int k = 0; k < z.n; k++) {
        tcb_npy a;
        memset(&err, 0, sizeof err);
        if (tcb_npz_read(&z, k, &a, &err)) {
            if (!strstr(err.msg, path)) fail_msg("'%s' does not name %s", err.msg, path);
        } else {
            tcb_npy_free(&a);
        }
    }
    tcb_npz_close(&z);
}

/* data[len] as path (plainly: tens of thousands of writes, no fsync). */
static void write_file(const char *path, const char *data, size_t len)
{
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(data, 1, len, f), len);
    assert_int_equal(fclose(f), 0);
}

static void test_damaged(void **state)
{
    (void)state;
    const char *tmp = "test_npz_damaged.npz";
    for (size_t f = 0; f < sizeof archives / sizeof archives[0]; f++) {
        char *data;
        size_t len;
        tcb_error err = {0};
        if (tcb_read_file(archives[f], &data, &len, &err)) fail_msg("%s", err.msg);
        /* every truncation */
        for (size_t cut = 0; cut < len; cut++) {
            write_file(tmp, data, cut);
            read_all(tmp);
        }
        /* each byte with its low bit, its high bit, all its bits flipped */
        for (size_t at = 0; at < len; at++) {
            static const unsigned char flips[] = {0x01, 0x80, 0xff};
            for (int v = 0; v < 3; v++) {
                char keep = data[at];
                data[at] = (char)(keep ^ flips[v]);
                write_file(tmp, data, len);
                read_all(tmp);
                data[at] = keep;
            }
        }
        free(data);
    }
    remove(tmp);
}

static void test_not_an_archive(void **state)
{
    (void)state;
    tcb_npz z;
    tcb_error err = {0};
    assert_int_equal(tcb_npz_open(DATA "make.py", &z, &err), TCB_ERR_INPUT);
    assert_non_null(strstr(err.msg, "make.py: not a ZIP archive (no end record)"));
    memset(&err, 0, sizeof err);
    assert_int_equal(tcb_npz_open(DATA "nowhere.npz", &z, &err), TCB_ERR_IO);
    assert_non_null(strstr(err.msg, "nowhere.npz: cannot open"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_read),
        cmocka_unit_test(test_damaged),
        cmocka_unit_test(test_not_an_archive),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
