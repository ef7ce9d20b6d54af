/* core/: errors, random streams, atomic files, emptying a directory, JSON
 * getters, progress. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "testutil.h"
#include "tcb/error.h"
#include "tcb/fsutil.h"
#include "tcb/json.h"
#include "tcb/progress.h"
#include "tcb/rng.h"

static int count_entries(const char *dir)
{
    DIR *d = opendir(dir);
    assert_non_null(d);
    int n = 0;
    for (struct dirent *e; (e = readdir(d));) n += e->d_name[0] != '.';
    closedir(d);
    return n;
}

static void test_error_prefix_keeps_message(void **state)
{
    (void)state;
    tcb_error err;
    assert_int_equal(tcb_fail(&err, TCB_ERR_INPUT, "line %d: bad", 7), TCB_ERR_INPUT);
    tcb_error_prefix(&err, "%s: ", "cat.obj");
    assert_string_equal(err.msg, "cat.obj: line 7: bad");
    assert_int_equal(tcb_status_exit_code(TCB_ERR_INPUT), 2);
    assert_int_equal(tcb_status_exit_code(TCB_ERR_IO), 2);
    assert_int_equal(tcb_status_exit_code(TCB_ERR_NUMERIC), 1);
    /* An over-long message is truncated, never overflowed. */
    char big[3000];
    memset(big, 'x', sizeof big - 1);
    big[sizeof big - 1] = '\0';
    tcb_fail(&err, TCB_ERR_IO, "%s", big);
    tcb_error_prefix(&err, "%s", big);
    assert_int_equal(strlen(err.msg), TCB_ERRMSG_MAX - 1);
    assert_int_equal(tcb_fail(NULL, TCB_ERR_IO, "dropped"), TCB_ERR_IO);
}

/* A message is one line whatever it quotes (found by the fuzz targets: a
 * JSON key holding a newline came out verbatim), also after a prefix. */
static void test_error_message_is_one_line(void **state)
{
    (void)state;
    tcb_error err = {0};
    tcb_fail(&err, TCB_ERR_INPUT, "f.json.%s: unknown key", "a\nb\tc\x1b[31m\x7f");
    assert_string_equal(err.msg, "f.json.a\\nb\\tc\\x1b[31m\\x7f: unknown key");
    tcb_error_prefix(&err, "run\r%s: ", "é");
    assert_string_equal(err.msg, "run\\ré: f.json.a\\nb\\tc\\x1b[31m\\x7f: unknown key");
}

static void test_rng_is_reproducible_and_streams_differ(void **state)
{
    (void)state;
    tcb_rng a, b, c;
    tcb_rng_seed(&a, 42);
    tcb_rng_seed(&b, 42);
    tcb_rng_seed_stream(&c, 42, "pool/cat");
    int differ = 0;
    for (int k = 0; k < 100; k++) {
        uint64_t x = tcb_rng_next(&a);
        assert_int_equal(x, tcb_rng_next(&b));
        differ += x != tcb_rng_next(&c);
    }
    assert_true(differ > 95);
    tcb_rng d, e;
    tcb_rng_seed_stream(&d, 42, "pool/cat");
    tcb_rng_seed_stream(&e, 42, "pool/dog");
    assert_true(tcb_rng_next(&d) != tcb_rng_next(&e));
}

static void test_rng_distributions(void **state)
{
    (void)state;
    tcb_rng r;
    tcb_rng_seed(&r, 7);
    enum { N = 60000, K = 6 };
    int counts[K] = {0};
    double sum = 0, sum2 = 0;
    for (int k = 0; k < N; k++) {
        uint32_t v = tcb_rng_below(&r, K);
        assert_true(v < K);
        counts[v]++;
        double u = tcb_rng_uniform(&r);
        assert_true(u >= 0 && u < 1);
        double z = tcb_rng_normal(&r);
        sum += z, sum2 += z * z;
    }
    /* Each bucket expects 10000 with sd ≈ 91: 5 sd is a fixed-seed bound. */
    for (int k = 0; k < K; k++) assert_true(abs(counts[k] - N / K) < 460);
    assert_true(fabs(sum / N) < 0.02);
    assert_true(fabs(sum2 / N - 1) < 0.03);
    int32_t perm[100];
    tcb_rng_permutation(&r, perm, 100);
    int seen[100] = {0};
    for (int k = 0; k < 100; k++) seen[perm[k]]++;
    for (int k = 0; k < 100; k++) assert_int_equal(seen[k], 1);
}

static void test_atomic_write_commit_and_abort(void **state)
{
    (void)state;
    char dir[512], path[1024];
    tu_make_tmpdir(dir, sizeof dir);
    snprintf(path, sizeof path, "%s/a/b/out.txt", dir);
    tcb_error err;
    tcb_atomic_file af;
    assert_int_equal(tcb_atomic_open(&af, path, &err), TCB_OK);
    fputs("half", af.fp);
    tcb_atomic_abort(&af);
    assert_false(tcb_is_file(path));
    char sub[1100];
    snprintf(sub, sizeof sub, "%s/a/b", dir);
    assert_int_equal(count_entries(sub), 0); /* no temporary left behind */

    assert_int_equal(tcb_write_file_atomic(path, "hello", 5, &err), TCB_OK);
    char *data;
    size_t len;
    assert_int_equal(tcb_read_file(path, &data, &len, &err), TCB_OK);
    assert_int_equal(len, 5);
    assert_string_equal(data, "hello");
    free(data);
    assert_int_equal(count_entries(sub), 1);

    assert_int_equal(tcb_read_file("/nonexistent/file", &data, &len, &err), TCB_ERR_IO);
    assert_non_null(strstr(err.msg, "/nonexistent/file"));
    assert_int_equal(tcb_read_file(dir, &data, &len, &err), TCB_ERR_IO);
    tu_remove_tree(dir);
}

/* Debris of killed writers goes; a live writer's temporary (this process's,
 * as from tcb_atomic_open) stays, and so does everything else. */
static void test_stale_temps_only(void **state)
{
    const char *dir = *state;
    char live[TCB_PATH_MAX], dead[TCB_PATH_MAX], odd[TCB_PATH_MAX], other[TCB_PATH_MAX], keep[TCB_PATH_MAX];
    tcb_error err;
    tcb_atomic_file af;
    snprintf(live, sizeof live, "%s/c.json", dir);
    assert_int_equal(tcb_atomic_open(&af, live, &err), TCB_OK);
    tu_write_text(dir, "c.json.tmp-2147483646-Ab12Cd", "", dead, sizeof dead); /* above any pid_max */
    tu_write_text(dir, "c.json.tmp-Ab12Cd", "", odd, sizeof odd);
    tu_write_text(dir, "d.json.tmp-2147483646-Ab12Cd", "", other, sizeof other);
    tu_write_text(dir, "c.json", "{}", keep, sizeof keep);
    tcb_remove_stale_temps(dir, "c.json.tmp-");
    assert_true(tcb_is_file(af.tmp));
    assert_false(tcb_is_file(dead));
    assert_false(tcb_is_file(odd));
    assert_true(tcb_is_file(other));
    assert_true(tcb_is_file(keep));
    tcb_remove_stale_temps(dir, "");
    assert_false(tcb_is_file(other));
    assert_true(tcb_is_file(af.tmp));
    assert_int_equal(tcb_atomic_commit(&af, &err), TCB_OK);
}

/* Everything below the directory goes, subdirectories too; a link goes,
 * never what it points to; a missing directory is empty. */
static void test_empty_dir(void **state)
{
    const char *dir = *state;
    char work[TCB_PATH_MAX], deep[TCB_PATH_MAX], outside[TCB_PATH_MAX], file[TCB_PATH_MAX], link[TCB_PATH_MAX];
    tcb_error err = {0};
    snprintf(work, sizeof work, "%s/work", dir);
    snprintf(deep, sizeof deep, "%s/work/model/a/b", dir);
    snprintf(outside, sizeof outside, "%s/outside", dir);
    assert_int_equal(tcb_mkdirs(deep, &err), TCB_OK);
    assert_int_equal(tcb_mkdirs(outside, &err), TCB_OK);
    tu_write_text(deep, "ckpt", "x", file, sizeof file);
    tu_write_text(work, "model.ckpt", "x", file, sizeof file);
    tu_write_text(outside, "kept", "x", file, sizeof file);
    snprintf(link, sizeof link, "%s/work/model/to_outside", dir);
    assert_int_equal(symlink(outside, link), 0);
    assert_int_equal(tcb_empty_dir(work, &err), TCB_OK);
    assert_true(tcb_is_dir(work));
    assert_int_equal(count_entries(work), 0);
    assert_true(tcb_is_file(file));
    assert_int_equal(count_entries(outside), 1);
    snprintf(work, sizeof work, "%s/missing", dir);
    assert_int_equal(tcb_empty_dir(work, &err), TCB_OK);
}

static void test_path_join_refuses_truncation(void **state)
{
    (void)state;
    char small[8];
    tcb_error err;
    assert_int_equal(tcb_path_join(small, sizeof small, &err, "%s/%s", "abc", "def"), TCB_OK);
    assert_int_equal(tcb_path_join(small, sizeof small, &err, "%s/%s", "abcd", "efgh"), TCB_ERR_INPUT);
}

static void test_json_errors_name_the_key(void **state)
{
    (void)state;
    cJSON *j;
    tcb_error err;
    assert_int_equal(tcb_json_parse("{\n  \"a\": 1,\n  \"b\": [1,\n}", "cfg.json", &j, &err), TCB_ERR_INPUT);
    assert_non_null(strstr(err.msg, "cfg.json:4:"));
    assert_int_equal(tcb_json_parse("{\"n\": 2.5, \"s\": \"x\", \"b\": true, \"k\": 12}", "cfg.json", &j, &err),
                     TCB_OK);
    long long i;
    double d;
    int b, idx;
    const char *s;
    assert_int_equal(tcb_json_int(j, "n", "cfg.json: top", 1, 0, 0, 10, &i, &err), TCB_ERR_INPUT);
    assert_non_null(strstr(err.msg, "cfg.json: top.n: expected an integer"));
    assert_int_equal(tcb_json_int(j, "k", "top", 1, 0, 0, 10, &i, &err), TCB_ERR_INPUT);
    assert_non_null(strstr(err.msg, "top.k: 12 is out of range"));
    assert_int_equal(tcb_json_int(j, "missing", "top", 0, 5, 0, 10, &i, &err), TCB_OK);
    assert_int_equal(i, 5);
    assert_int_equal(tcb_json_int(j, "missing", "top", 1, 5, 0, 10, &i, &err), TCB_ERR_INPUT);
    assert_non_null(strstr(err.msg, "top.missing: required key is missing"));
    assert_int_equal(tcb_json_num(j, "s", "top", 1, 0, 0, 1, &d, &err), TCB_ERR_INPUT);
    assert_non_null(strstr(err.msg, "top.s: expected a number, got a string"));
    assert_int_equal(tcb_json_bool(j, "b", "top", 1, 0, &b, &err), TCB_OK);
    assert_true(b);
    assert_int_equal(tcb_json_str(j, "b", "top", 1, NULL, &s, &err), TCB_ERR_INPUT);
    const char *const choices[] = {"x", "y", NULL};
    assert_int_equal(tcb_json_enum(j, "s", "top", 1, -1, choices, &idx, &err), TCB_OK);
    assert_int_equal(idx, 0);
    const char *const other[] = {"p", "q", NULL};
    assert_int_equal(tcb_json_enum(j, "s", "top", 1, -1, other, &idx, &err), TCB_ERR_INPUT);
    assert_non_null(strstr(err.msg, "expected one of: p, q"));
    const char *const allowed[] = {"n", "s", "b", NULL};
    assert_int_equal(tcb_json_expect_keys(j, "top", allowed, &err), TCB_ERR_INPUT);
    assert_non_null(strstr(err.msg, "top.k: unknown key"));
    cJSON_Delete(j);
}

static void test_progress_plain_lines_when_not_a_tty(void **state)
{
    (void)state;
    char dir[512], path[1024];
    tu_make_tmpdir(dir, sizeof dir);
    snprintf(path, sizeof path, "%s/log.txt", dir);
    FILE *f = fopen(path, "w+");
    tcb_term_progress tp;
    tcb_term_progress_init(&tp, f, 0);
    tcb_reporter r = tcb_term_progress_reporter(&tp);
    for (int k = 0; k <= 100; k++) tcb_report_progress(&r, k, 100, "cell");
    tcb_report_log(&r, TCB_LOG_INFO, "done %d", 1);
    rewind(f);
    int lines = 0;
    char buf[256];
    while (fgets(buf, sizeof buf, f)) lines++;
    assert_int_equal(lines, 2 + 1); /* start, end, and the log line */
    fclose(f);

    f = fopen(path, "w+");
    tcb_term_progress_init(&tp, f, 1); /* quiet: nothing but warnings */
    r = tcb_term_progress_reporter(&tp);
    tcb_report_progress(&r, 1, 2, "cell");
    tcb_report_log(&r, TCB_LOG_INFO, "hidden");
    tcb_report_log(&r, TCB_LOG_WARN, "shown");
    rewind(f);
    assert_non_null(fgets(buf, sizeof buf, f));
    assert_string_equal(buf, "warning: shown\n");
    assert_null(fgets(buf, sizeof buf, f));
    fclose(f);
    tu_remove_tree(dir);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_error_prefix_keeps_message),
        cmocka_unit_test(test_error_message_is_one_line),
        cmocka_unit_test(test_rng_is_reproducible_and_streams_differ),
        cmocka_unit_test(test_rng_distributions),
        cmocka_unit_test(test_atomic_write_commit_and_abort),
        cmocka_unit_test_setup_teardown(test_stale_temps_only, tu_setup_tmpdir, tu_teardown_tmpdir),
        cmocka_unit_test_setup_teardown(test_empty_dir, tu_setup_tmpdir, tu_teardown_tmpdir),
        cmocka_unit_test(test_path_join_refuses_truncation),
        cmocka_unit_test(test_json_errors_name_the_key),
        cmocka_unit_test(test_progress_plain_lines_when_not_a_tty),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
