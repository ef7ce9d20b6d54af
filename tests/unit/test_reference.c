/* The paper's numbers as data (references/iccv21.json, built in): every
 * table there, consistent with itself where the paper repeats a number
 * (reference-protocol §8: the cross-table identities and the MEAN rows of
 * §5.6), and a strict reader whose errors name the key. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "reports/reference.h"
#include "testutil.h"

static tcb_reference iccv21;

static int setup(void **state)
{
    (void)state;
    tcb_error err = {0};
    if (tcb_reference_load("iccv21", &iccv21, &err)) {
        fprintf(stderr, "%s\n", err.msg);
        return -1;
    }
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    tcb_reference_free(&iccv21);
    return 0;
}

static const tcb_ref_row *row(const char *table, const char *dataset, const char *sequence, const char *method)
{
    const tcb_ref_table *t = tcb_reference_table(&iccv21, table);
    for (int k = 0; t && k < t->n_rows; k++)
        if (!strcmp(t->rows[k].dataset, dataset) && !strcmp(t->rows[k].sequence, sequence) &&
            !strcmp(t->rows[k].method, method))
            return &t->rows[k];
    fail_msg("table %s has no row %s/%s/%s", table, dataset, sequence, method);
    return NULL;
}

/* Same numbers in every metric both rows report, to the paper's rounding. */
static void assert_same(const tcb_ref_row *a, const tcb_ref_row *b, double tol)
{
    for (int m = 0; m < TCB_N_METRICS; m++) {
        if (!a->has[m] || !b->has[m]) continue;
        if (fabs(a->mean[m] - b->mean[m]) > tol || (a->has_std[m] && b->has_std[m] && fabs(a->std[m] - b->std[m]) > tol))
            fail_msg("%s and %s differ in metric %d", a->paper_row, b->paper_row, m);
    }
}

static void test_every_table(void **state)
{
    (void)state;
    static const char *const ids[] = {"1", "2", "3", "4", "5", "6", "7", "8", "9", "10"};
    static const int rows[] = {15, 2, 24, 6, 4, 18, 25, 55, 75, 15};
    assert_int_equal(iccv21.n_tables, 10);
    for (int k = 0; k < 10; k++) {
        const tcb_ref_table *t = tcb_reference_table(&iccv21, ids[k]);
        assert_non_null(t);
        assert_int_equal(t->n_rows, rows[k]);
    }
    const tcb_ref_row *r = row("5", "ama", "crane", "propagate_bijective");
    assert_true(r->has[0] && !r->has[3]);
    assert_true(fabs(r->mean[0] - 213.87) < 1e-9 && fabs(r->std[0] - 169.00) < 1e-9);
}

static void test_cross_table_identities(void **state)
{
    (void)state;
    assert_same(row("2", "ama", "crane", "neighbors"), row("6", "ama", "crane", "delta_1"), 0);
    assert_same(row("2", "ama", "crane", "neighbors"), row("8", "ama", "crane", "mca"), 0);
    assert_same(row("5", "ama", "crane", "random"), row("8", "ama", "crane", "nricp"), 0);
    assert_same(row("4", "dfaust", "jumping_jacks", "random"), row("9", "dfaust", "jumping_jacks", "cc"), 0);
    assert_same(row("4", "dfaust", "jiggle_on_toes", "random"), row("9", "dfaust", "jiggle_on_toes", "cc"), 0);
    /* Table 3 prints one decimal */
    assert_same(row("3", "anim", "cat_walk", "alpha_0.1"), row("7", "anim", "cat_walk", "mca"), 0.05);
    assert_same(row("3", "ama", "crane", "alpha_0.1"), row("8", "ama", "crane", "mca"), 0.05);
    assert_same(row("3", "dfaust", "jumping_jacks", "alpha_0.1_delta5"), row("9", "dfaust", "jumping_jacks", "mca"),
                0.05);
    static const char *const ds[] = {"anim", "ama", "dfaust"}, *const per[] = {"7", "8", "9"};
    static const char *const methods[] = {"nricp", "atlasnet", "dsr", "cc", "mca"};
    for (int d = 0; d < 3; d++)
        for (int m = 0; m < 5; m++) assert_same(row("1", ds[d], "MEAN", methods[m]), row(per[d], ds[d], "MEAN", methods[m]), 0);
}

/* §5.6: MEAN = the mean over the test sequences of the per-sequence means,
 * and of the stds; DFAUST's stds are averaged over all 14 (the paper's own
 * inconsistency, kept as printed). */
static void check_means(const char *table, const char *dataset, const char *validation, int stds_over_all)
{
    const tcb_ref_table *t = tcb_reference_table(&iccv21, table);
    static const char *const methods[] = {"nricp", "atlasnet", "dsr", "cc", "mca"};
    for (int k = 0; k < 5; k++) {
        const tcb_ref_row *mean = row(table, dataset, "MEAN", methods[k]);
        for (int m = 0; m < TCB_N_METRICS; m++) {
            if (!mean->has[m]) continue;
            double sum = 0, sum_std = 0;
            int n = 0, n_std = 0;
            for (int r = 0; r < t->n_rows; r++) {
                const tcb_ref_row *x = &t->rows[r];
                if (strcmp(x->method, methods[k]) || !strcmp(x->sequence, "MEAN")) continue;
                int test = !validation || strcmp(x->sequence, validation);
                if (test) sum += x->mean[m], n++;
                if (test || stds_over_all) sum_std += x->std[m], n_std++;
            }
            if (fabs(sum / n - mean->mean[m]) > 0.011 || fabs(sum_std / n_std - mean->std[m]) > 0.011)
                fail_msg("table %s %s metric %d: MEAN %.2f ± %.2f, sequences give %.3f ± %.3f", table, methods[k], m,
                         mean->mean[m], mean->std[m], sum / n, sum_std / n_std);
        }
    }
}

static void test_mean_rows(void **state)
{
    (void)state;
    check_means("7", "anim", "cat_walk", 0);
    check_means("8", "ama", "crane", 0);
    check_means("9", "dfaust", "jumping_jacks", 1);
    check_means("10", "anim", NULL, 0);
}

static void test_bad_files(void **state)
{
    (void)state;
    static const char *const cases[][2] = {
        {"{\"format\": \"tcbench-reference/2\", \"name\": \"x\", \"paper\": \"p\", \"tables\": []}",
         "r.json: format: 'tcbench-reference/2', expected 'tcbench-reference/1'"},
        {"{\"format\": \"tcbench-reference/1\", \"name\": \"x\", \"paper\": \"p\", \"tables\": []}",
         "r.json: tables: expected a non-empty array"},
        {"{\"format\": \"tcbench-reference/1\", \"name\": \"x\", \"paper\": \"p\", \"tables\": [{\"id\": \"1\", "
         "\"title\": \"t\", \"rows\": [{\"paper_row\": \"a\", \"dataset\": \"d\", \"sequence\": \"s\", \"method\": "
         "\"m\", \"sl2\": [1], \"rank\": null, \"auc\": null, \"cd\": null}]}]}",
         "r.json: tables[0].rows[0].sl2: expected null or [mean, std]"},
        {"{\"format\": \"tcbench-reference/1\", \"name\": \"x\", \"paper\": \"p\", \"tables\": [{\"id\": \"1\", "
         "\"title\": \"t\", \"rows\": [{\"paper_row\": \"a\", \"dataset\": \"d\", \"sequence\": \"s\", \"method\": "
         "\"m\", \"sl2\": null, \"rank\": null, \"auc\": null}]}]}",
         "r.json: tables[0].rows[0].cd: required key is missing"},
        {"{\"format\": \"tcbench-reference/1\", \"name\": \"x\", \"paper\": \"p\", \"extra\": 1, \"tables\": []}",
         "r.json.extra: unknown key"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        tcb_reference r;
        tcb_error err = {0};
        int rc = tcb_reference_parse(cases[k][0], "r.json", &r, &err);
        if (rc != TCB_ERR_INPUT || !strstr(err.msg, cases[k][1]))
            fail_msg("case %zu: rc %d, message \"%s\", expected \"%s\"", k, rc, err.msg, cases[k][1]);
    }
    tcb_reference r;
    tcb_error err = {0};
    assert_int_equal(tcb_reference_load("iccv22", &r, &err), TCB_ERR_INPUT);
    assert_non_null(strstr(err.msg, "--reference iccv22: no such built-in reference"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_every_table),
        cmocka_unit_test(test_cross_table_identities),
        cmocka_unit_test(test_mean_rows),
        cmocka_unit_test(test_bad_files),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
