/* Regression check: a baseline written from a run checks clean; values
 * moved beyond their tolerance, changed statuses and rows the run lacks
 * drift; rows the baseline does not name are listed as not in the baseline
 * without drifting; malformed baselines are input errors naming the file. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "fake_run.h"
#include "tcb/json.h"
#include "tcb/report.h"
#include "testutil.h"

typedef struct fixture {
    char dir[512];
    char baseline[1024];
} fixture;

static const fake_cell CELLS[] = {
    {"anim", "cat", "validation", "AN", 0, TCB_CELL_OK, 0.03, 1, 0},
    {"anim", "horse", "test", "AN", 0, TCB_CELL_OK, 0.01, 1, 0},
    {"anim", "horse", "test", "AN", 1, TCB_CELL_OK, 0.01, 1, 0},
    {"anim", "horse", "test", "NN", 0, TCB_CELL_OK, 0.02, 0, 0},
    {"anim", "horse", "test", "DSR", 0, TCB_CELL_DIVERGED, 0.01, 1, 0},
};
#define N_CELLS ((int)(sizeof CELLS / sizeof CELLS[0]))

static int setup(void **state)
{
    fixture *f = calloc(1, sizeof *f);
    tu_make_tmpdir(f->dir, sizeof f->dir);
    for (int k = 0; k < N_CELLS; k++)
        if (fake_write(f->dir, &CELLS[k])) return -1;
    snprintf(f->baseline, sizeof f->baseline, "%s/baseline.json", f->dir);
    tcb_error err = {0};
    if (tcb_baseline_write(f->dir, f->baseline, &err)) {
        fprintf(stderr, "%s\n", err.msg);
        return -1;
    }
    *state = f;
    return 0;
}

static int teardown(void **state)
{
    fixture *f = *state;
    tu_remove_tree(f->dir);
    free(f);
    return 0;
}

/* Runs the check; returns the drift count, the diff table in *table. */
static int check(const fixture *f, const char *baseline, char **table)
{
    size_t len;
    FILE *out = open_memstream(table, &len);
    assert_non_null(out);
    int n_drift = -1;
    tcb_error err = {0};
    int rc = tcb_check(f->dir, baseline, out, &n_drift, &err);
    fclose(out);
    if (rc) fail_msg("tcb_check: %s", err.msg);
    return n_drift;
}

/* The baseline with the row (sequence, method) edited by `edit`, saved next
 * to the original as `name`. */
typedef void (*row_edit)(cJSON *root, cJSON *row);

static void edited(const fixture *f, const char *sequence, const char *method, row_edit edit,
                   const char *name, char *out, size_t size)
{
    cJSON *root;
    tcb_error err = {0};
    assert_int_equal(tcb_json_load(f->baseline, &root, &err), TCB_OK);
    cJSON *row = NULL;
    for (cJSON *r = cJSON_GetObjectItem(root, "rows")->child; r; r = r->next)
        if (!strcmp(cJSON_GetObjectItem(r, "sequence")->valuestring, sequence) &&
            !strcmp(cJSON_GetObjectItem(r, "method")->valuestring, method))
            row = r;
    assert_non_null(row);
    edit(root, row);
    snprintf(out, size, "%s/%s", f->dir, name);
    assert_int_equal(tcb_json_save(out, root, &err), TCB_OK);
    cJSON_Delete(root);
}

/* The lines of `table` that end in DRIFT. */
static int drift_lines(const char *table, char lines[][256], int max)
{
    int n = 0;
    for (const char *p = table; *p && n < max;) {
        const char *end = strchr(p, '\n');
        size_t len = end ? (size_t)(end - p) : strlen(p);
        if (len >= 5 && !strncmp(p + len - 5, "DRIFT", 5))
            snprintf(lines[n++], 256, "%.*s", (int)len, p);
        p += len + (end != NULL);
    }
    return n;
}

static void test_baseline_checks_clean(void **state)
{
    fixture *f = *state;
    char *table;
    assert_int_equal(check(f, f->baseline, &table), 0);
    assert_null(strstr(table, "DRIFT"));
    assert_non_null(strstr(table, "anim/horse/DSR"));
    assert_non_null(strstr(table, "0 drift"));
    free(table);
}

static void shift_metric(cJSON *row, const char *metric, double by)
{
    cJSON *v = cJSON_GetObjectItem(row, metric);
    cJSON_SetNumberValue(v, v->valuedouble + by);
}
static void shift(cJSON *row, double by) { shift_metric(row, "sl2", by); }

/* Checks the baseline at path: exactly one row drifts, on one line, which
 * contains every one of the n needles. */
static void expect_one_drift(const fixture *f, const char *path, int n, const char *const *needles)
{
    char *table, lines[8][256];
    assert_int_equal(check(f, path, &table), 1);
    assert_int_equal(drift_lines(table, lines, 8), 1);
    for (int k = 0; k < n; k++)
        if (!strstr(lines[0], needles[k])) fail_msg("no \"%s\" in: %s", needles[k], lines[0]);
    free(table);
}
static void beyond_tolerance(cJSON *root, cJSON *row) { (void)root, shift(row, 1e-3); }
static void within_tolerance(cJSON *root, cJSON *row) { (void)root, shift(row, 5e-7); }

static void test_drift_beyond_tolerance(void **state)
{
    fixture *f = *state;
    char path[2048], *table;
    edited(f, "horse", "AN", beyond_tolerance, "beyond.json", path, sizeof path);
    expect_one_drift(f, path, 3, (const char *const[]){"anim/horse/AN ", " sl2 ", "-1.000e-03"});
    edited(f, "horse", "AN", within_tolerance, "within.json", path, sizeof path);
    assert_int_equal(check(f, path, &table), 0);
    free(table);
}

/* rel = 1e-3 lets sl2 move by 0.1 %: 0.05 % passes, 0.2 % drifts. */
static void loosen(cJSON *root, cJSON *row, double fraction)
{
    cJSON *t = cJSON_GetObjectItem(cJSON_GetObjectItem(root, "tolerances"), "sl2");
    cJSON_SetNumberValue(cJSON_GetObjectItem(t, "abs"), 0);
    cJSON_SetNumberValue(cJSON_GetObjectItem(t, "rel"), 1e-3);
    shift(row, fraction * cJSON_GetObjectItem(row, "sl2")->valuedouble);
}
static void loosen_small(cJSON *root, cJSON *row) { loosen(root, row, 5e-4); }
static void loosen_large(cJSON *root, cJSON *row) { loosen(root, row, 2e-3); }

static void test_relative_tolerance(void **state)
{
    fixture *f = *state;
    char path[2048], *table;
    edited(f, "cat", "AN", loosen_small, "rel_small.json", path, sizeof path);
    assert_int_equal(check(f, path, &table), 0);
    free(table);
    edited(f, "cat", "AN", loosen_large, "rel_large.json", path, sizeof path);
    assert_int_equal(check(f, path, &table), 1);
    free(table);
}

static void cd_appears(cJSON *root, cJSON *row)
{
    (void)root;
    cJSON_ReplaceItemInObject(row, "cd", cJSON_CreateNumber(0.1));
}
static void status_changes(cJSON *root, cJSON *row)
{
    (void)root;
    cJSON_ReplaceItemInObject(row, "status", cJSON_CreateString("failed"));
}

/* A row's own tolerances: sl2 ±2e-3 on horse/AN alone. A 1e-3 shift
 * passes there, while the same shift of another row still drifts; a
 * malformed row tolerance is refused naming its key. */
static void own_tolerance(cJSON *root, cJSON *row)
{
    (void)root;
    cJSON *t = cJSON_AddObjectToObject(row, "tolerances"), *m = cJSON_AddObjectToObject(t, "sl2");
    cJSON_AddNumberToObject(m, "abs", 2e-3), cJSON_AddNumberToObject(m, "rel", 0);
    shift(row, 1e-3);
}
static void own_tolerance_bad(cJSON *root, cJSON *row)
{
    (void)root;
    cJSON *t = cJSON_AddObjectToObject(row, "tolerances"), *m = cJSON_AddObjectToObject(t, "sl2");
    cJSON_AddNumberToObject(m, "abs", -1), cJSON_AddNumberToObject(m, "rel", 0);
}

static void test_row_tolerance(void **state)
{
    fixture *f = *state;
    char path[2048], *table, lines[8][256];
    edited(f, "horse", "AN", own_tolerance, "own.json", path, sizeof path);
    assert_int_equal(check(f, path, &table), 0);
    assert_non_null(strstr(table, "2.0e-03"));
    free(table);
    edited(f, "cat", "AN", own_tolerance, "own_cat.json", path, sizeof path);
    assert_int_equal(check(f, path, &table), 0);
    free(table);
    edited(f, "horse", "AN", beyond_tolerance, "beyond2.json", path, sizeof path);
    assert_int_equal(check(f, path, &table), 1);
    assert_int_equal(drift_lines(table, lines, 8), 1);
    free(table);
    edited(f, "horse", "AN", own_tolerance_bad, "own_bad.json", path, sizeof path);
    int n_drift = -1;
    tcb_error err = {0};
    assert_int_equal(tcb_check(f->dir, path, NULL, &n_drift, &err), TCB_ERR_INPUT);
    if (!strstr(err.msg, "tolerances.sl2.abs") || !strstr(err.msg, "rows["))
        fail_msg("message: %s", err.msg);
}

/* A wider file tolerance for rank and a row's own for sl2. */
static void person_tolerances(cJSON *root, cJSON *row)
{
    cJSON *rank = cJSON_GetObjectItem(cJSON_GetObjectItem(root, "tolerances"), "rank");
    cJSON_ReplaceItemInObject(rank, "abs", cJSON_CreateNumber(0.5));
    cJSON *t = cJSON_AddObjectToObject(row, "tolerances"), *m = cJSON_AddObjectToObject(t, "sl2");
    cJSON_AddNumberToObject(m, "abs", 2e-3), cJSON_AddNumberToObject(m, "rel", 0.25);
}

/* --update rewrites the values but keeps the tolerances a person set: the
 * file's, and a row's own (that row only); a baseline that does not load
 * is left as it is, with an error naming it. */
static void test_update_keeps_tolerances(void **state)
{
    fixture *f = *state;
    char path[2048];
    edited(f, "horse", "AN", person_tolerances, "person.json", path, sizeof path);
    tcb_error err = {0};
    assert_int_equal(tcb_baseline_write(f->dir, path, &err), TCB_OK);
    cJSON *root;
    assert_int_equal(tcb_json_load(path, &root, &err), TCB_OK);
    cJSON *tol = cJSON_GetObjectItem(root, "tolerances");
    assert_true(cJSON_GetObjectItem(cJSON_GetObjectItem(tol, "rank"), "abs")->valuedouble == 0.5);
    assert_true(cJSON_GetObjectItem(cJSON_GetObjectItem(tol, "sl2"), "abs")->valuedouble == 1e-6);
    int own = 0;
    for (cJSON *r = cJSON_GetObjectItem(root, "rows")->child; r; r = r->next) {
        cJSON *t = cJSON_GetObjectItem(r, "tolerances");
        if (!t) continue;
        own++;
        assert_string_equal(cJSON_GetObjectItem(r, "sequence")->valuestring, "horse");
        assert_string_equal(cJSON_GetObjectItem(r, "method")->valuestring, "AN");
        cJSON *sl2 = cJSON_GetObjectItem(t, "sl2");
        assert_true(cJSON_GetObjectItem(sl2, "abs")->valuedouble == 2e-3);
        assert_true(cJSON_GetObjectItem(sl2, "rel")->valuedouble == 0.25);
        assert_int_equal(cJSON_GetArraySize(t), 1);
    }
    assert_int_equal(own, 1);
    cJSON_Delete(root);
    char *table;
    assert_int_equal(check(f, path, &table), 0);
    free(table);

    FILE *bad = fopen(path, "w");
    assert_non_null(bad);
    fputs("{\"format\": ", bad);
    fclose(bad);
    assert_int_equal(tcb_baseline_write(f->dir, path, &err), TCB_ERR_INPUT);
    if (!strstr(err.msg, "cannot keep the tolerances") || !strstr(err.msg, "person.json"))
        fail_msg("message: %s", err.msg);
    char text[64] = {0};
    bad = fopen(path, "r");
    assert_non_null(bad);
    assert_non_null(fgets(text, sizeof text, bad));
    fclose(bad);
    assert_string_equal(text, "{\"format\": ");
}

static void test_null_and_status_mismatch_drift(void **state)
{
    fixture *f = *state;
    char path[2048], *table, lines[8][256];
    edited(f, "horse", "NN", cd_appears, "cd.json", path, sizeof path);
    assert_int_equal(check(f, path, &table), 1);
    assert_int_equal(drift_lines(table, lines, 8), 1);
    assert_non_null(strstr(lines[0], "anim/horse/NN "));
    assert_non_null(strstr(lines[0], " cd "));
    free(table);
    edited(f, "horse", "DSR", status_changes, "status.json", path, sizeof path);
    assert_int_equal(check(f, path, &table), 1);
    assert_int_equal(drift_lines(table, lines, 8), 1);
    assert_non_null(strstr(lines[0], "failed"));
    assert_non_null(strstr(lines[0], "diverged"));
    free(table);
}

static void drop_row(cJSON *root, cJSON *row)
{
    cJSON_Delete(cJSON_DetachItemViaPointer(cJSON_GetObjectItem(root, "rows"), row));
}

/* The table's line for `row` (e.g. "anim/horse/NN "), in out[256]; 0 when there is none. */
static int row_line(const char *table, const char *row, char *out)
{
    const char *p = strstr(table, row);
    if (!p) return 0;
    snprintf(out, 256, "%.*s", (int)strcspn(p, "\n"), p);
    return 1;
}

/* row moved out of its tolerance, and horse/NN dropped. */
static void drop_nn_shift_row(cJSON *root, cJSON *row)
{
    shift(row, 1.0);
    for (cJSON *r = cJSON_GetObjectItem(root, "rows")->child; r; r = r->next)
        if (!strcmp(cJSON_GetObjectItem(r, "method")->valuestring, "NN")) {
            drop_row(root, r);
            return;
        }
    fail_msg("no NN row");
}

static void test_rows_not_in_the_baseline_are_listed_not_judged(void **state)
{
    fixture *f = *state;
    char path[2048], *table, lines[8][256], line[256];
    /* The run has a row the baseline lacks (a method scored beside the baseline's). */
    edited(f, "horse", "NN", drop_row, "dropped.json", path, sizeof path);
    assert_int_equal(check(f, path, &table), 0);
    assert_int_equal(drift_lines(table, lines, 8), 0);
    assert_true(row_line(table, "anim/horse/NN ", line));
    assert_non_null(strstr(line, "absent"));
    assert_non_null(strstr(line, "present"));
    assert_non_null(strstr(line, "not in the baseline"));
    assert_non_null(strstr(table, "3 baseline rows, 4 current rows: 0 drift (0 missing), 1 not in the baseline\n"));
    free(table);
    /* The extra row does not hide a drifted one beside it. */
    edited(f, "cat", "AN", drop_nn_shift_row, "dropped_shifted.json", path, sizeof path);
    assert_int_equal(check(f, path, &table), 1);
    assert_int_equal(drift_lines(table, lines, 8), 1);
    assert_non_null(strstr(lines[0], "anim/cat/AN "));
    assert_non_null(strstr(table, "1 drift (0 missing), 1 not in the baseline\n"));
    free(table);
}

static void test_rows_the_run_lacks_drift(void **state)
{
    fixture *f = *state;
    char *table, lines[8][256];
    char cell[2048];
    tcb_error err = {0};
    assert_int_equal(tcb_cell_path(cell, sizeof cell, f->dir, "anim", "cat", "AN", 0, &err), 0);
    assert_int_equal(unlink(cell), 0);
    assert_int_equal(check(f, f->baseline, &table), 1);
    assert_int_equal(drift_lines(table, lines, 8), 1);
    assert_non_null(strstr(lines[0], "anim/cat/AN "));
    assert_non_null(strstr(lines[0], "present"));
    assert_non_null(strstr(lines[0], "missing"));
    assert_non_null(strstr(table, "4 baseline rows, 3 current rows: 1 drift (1 missing), 0 not in the baseline\n"));
    free(table);
    assert_int_equal(fake_write(f->dir, &CELLS[0]), 0);
}

/* The geodesic error drifts like any metric. */
static void geo_moves(cJSON *root, cJSON *row) { (void)root, shift_metric(row, "geo", 1e-3); }

/* A baseline written before the geodesic error: no geodesic values, no
 * geodesic tolerances. */
static void strip_geodesic(cJSON *root, cJSON *row)
{
    (void)row;
    cJSON *t = cJSON_GetObjectItem(root, "tolerances"), *r;
    cJSON_DeleteItemFromObject(t, "geo");
    cJSON_DeleteItemFromObject(t, "geo_auc");
    cJSON_ArrayForEach(r, cJSON_GetObjectItem(root, "rows"))
    {
        cJSON_DeleteItemFromObject(r, "geo");
        cJSON_DeleteItemFromObject(r, "geo_auc");
    }
}
static void strip_geodesic_and_shift(cJSON *root, cJSON *row)
{
    strip_geodesic(root, row);
    shift(row, 1e-3);
}

static int count(const char *text, const char *needle)
{
    int n = 0;
    for (const char *p = text; (p = strstr(p, needle)); p++) n++;
    return n;
}

static void test_geodesic(void **state)
{
    fixture *f = *state;
    char path[2048], *table, lines[8][256];
    edited(f, "horse", "AN", geo_moves, "geo.json", path, sizeof path);
    expect_one_drift(f, path, 2, (const char *const[]){"anim/horse/AN ", " geo "});
    /* An old baseline still checks the paper's metrics, lists the
     * geodesic ones as unchecked and finds no drift; it still catches a
     * moved m_sL2. */
    edited(f, "horse", "AN", strip_geodesic, "old.json", path, sizeof path);
    assert_int_equal(check(f, path, &table), 0);
    assert_int_equal(count(table, "unchecked"), 2 * 3); /* geo, geo_auc of the 3 ok rows */
    assert_non_null(strstr(table, " sl2 "));
    free(table);
    edited(f, "horse", "AN", strip_geodesic_and_shift, "old_moved.json", path, sizeof path);
    expect_one_drift(f, path, 2, (const char *const[]){"anim/horse/AN ", " sl2 "});
    /* A run whose cell has no geodesic values (written before them) drifts
     * against a baseline that has them. */
    fake_cell old = CELLS[1];
    old.no_geo = 1;
    assert_int_equal(fake_write(f->dir, &old), 0);
    assert_int_equal(check(f, f->baseline, &table), 1);
    assert_int_equal(drift_lines(table, lines, 8), 2);
    assert_non_null(strstr(lines[0], " geo "));
    assert_non_null(strstr(lines[1], " geo_auc "));
    free(table);
    assert_int_equal(fake_write(f->dir, &CELLS[1]), 0);
}

static void expect_malformed(const fixture *f, const char *text, const char *key)
{
    char path[2048];
    tu_write_text(f->dir, "bad.json", text, path, sizeof path);
    int n_drift = -1;
    tcb_error err = {0};
    assert_int_equal(tcb_check(f->dir, path, NULL, &n_drift, &err), TCB_ERR_INPUT);
    if (!strstr(err.msg, path) || !strstr(err.msg, key))
        fail_msg("message \"%s\" does not name %s and %s", err.msg, path, key);
}

#define TOL "{\"abs\": 0, \"rel\": 0}"
#define TOLS                                                                                       \
    "\"tolerances\": {\"sl2\": " TOL ", \"rank\": " TOL ", \"auc\": " TOL ", \"cd\": " TOL "}"
#define ROW(m) "{\"dataset\": \"anim\", \"sequence\": \"cat\", \"method\": \"" m "\", " \
               "\"sl2\": 1, \"rank\": 1, \"auc\": 1, \"cd\": null}"

static void test_malformed_baselines(void **state)
{
    fixture *f = *state;
    expect_malformed(f, "{\"format\": ", ":1:");
    expect_malformed(f, "{\"format\": \"tcbench-baseline/0\", " TOLS ", \"rows\": []}", "format");
    expect_malformed(f, "{\"format\": \"tcbench-baseline/1\", " TOLS ", \"rows\": [], \"x\": 1}",
                     ": x:");
    expect_malformed(f,
                     "{\"format\": \"tcbench-baseline/1\", \"tolerances\": {\"sl2\": " TOL
                     ", \"rank\": " TOL ", \"auc\": " TOL "}, \"rows\": []}",
                     "tolerances.cd");
    expect_malformed(f,
                     "{\"format\": \"tcbench-baseline/1\", \"tolerances\": {\"sl2\": {\"abs\": -1, "
                     "\"rel\": 0}, \"rank\": " TOL ", \"auc\": " TOL ", \"cd\": " TOL
                     "}, \"rows\": []}",
                     "tolerances.sl2.abs");
    expect_malformed(f,
                     "{\"format\": \"tcbench-baseline/1\", " TOLS
                     ", \"rows\": [{\"dataset\": \"anim\", "
                     "\"sequence\": \"cat\", \"method\": \"AN\", \"sl2\": \"1\", \"rank\": 1, "
                     "\"auc\": 1, \"cd\": null}]}",
                     "rows[0].sl2");
    expect_malformed(f,
                     "{\"format\": \"tcbench-baseline/1\", " TOLS
                     ", \"rows\": [" ROW("AN") ", " ROW("AN") "]}",
                     "rows[1]");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_baseline_checks_clean),
        cmocka_unit_test(test_drift_beyond_tolerance),
        cmocka_unit_test(test_relative_tolerance),
        cmocka_unit_test(test_row_tolerance),
        cmocka_unit_test(test_update_keeps_tolerances),
        cmocka_unit_test(test_null_and_status_mismatch_drift),
        cmocka_unit_test(test_rows_not_in_the_baseline_are_listed_not_judged),
        cmocka_unit_test(test_rows_the_run_lacks_drift),
        cmocka_unit_test(test_geodesic),
        cmocka_unit_test(test_malformed_baselines),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
