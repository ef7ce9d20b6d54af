/* Paired comparisons from cells (tcb/compare.h) on cases computed by hand,
 * and the marks they put in a report's tables (reports/significance.c):
 * a constant difference on every pair gives that constant as the interval
 * and Wilcoxon's exact p = 2 / 2^P; identical methods a 0 difference, no
 * test and a tie; the seed level of the bootstrap; splits that differ are
 * refused; the MEAN comparison resamples sequences. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "reports/aggregate.h"
#include "tcb/compare.h"
#include "testutil.h"

enum { P = 20, MAXC = 8 };

typedef struct cells {
    tcb_cell_result c[MAXC];
    tcb_pair_record pairs[MAXC][P];
    int n;
} cells;

/* A cell of `method`, seed s, whose pair p scores m_sL2 = (base(p) + off)
 * × 1e-3 (so table units base(p) + off), rank and AUC derived from it; no
 * CD, no geodesic error. base(p) varies so that nothing is constant by
 * accident. */
static tcb_cell_result *add(cells *cs, const char *sequence, const char *method, int seed, double off)
{
    assert_true(cs->n < MAXC);
    tcb_cell_result *c = &cs->c[cs->n];
    tcb_pair_record *pr = cs->pairs[cs->n++];
    memset(c, 0, sizeof *c);
    snprintf(c->dataset, sizeof c->dataset, "anim");
    snprintf(c->sequence, sizeof c->sequence, "%s", sequence);
    snprintf(c->role, sizeof c->role, "test");
    snprintf(c->method, sizeof c->method, "%s", method);
    snprintf(c->split_path, sizeof c->split_path, "splits/anim/%s.json", sequence);
    c->seed = seed, c->status = TCB_CELL_OK, c->n_pairs = P, c->pairs = pr;
    tcb_summary_init(&c->summary);
    for (int p = 0; p < P; p++) {
        double v = 5.0 + (double)((p * 7) % 11) + off;
        memset(&pr[p], 0, sizeof pr[p]);
        pr[p].i = p % 4, pr[p].j = p % 4 + 1; /* (i, j) repeat: pairing is by position */
        pr[p].sl2 = (tcb_stat){4, v * 1e-3, 0};
        pr[p].rank = (tcb_stat){4, v * 1e-4, 0};
        pr[p].auc = 1.0 - v * 1e-3;
        pr[p].cd = NAN;
        tcb_stat_merge(&c->summary.sl2, &pr[p].sl2);
        tcb_stat_merge(&c->summary.rank, &pr[p].rank);
        tcb_stat_push(&c->summary.auc, pr[p].auc);
    }
    c->summary.n_pairs = P;
    return c;
}

static void test_constant_difference(void **state)
{
    (void)state;
    cells cs = {.n = 0};
    add(&cs, "horse", "A", 0, 0.0);
    add(&cs, "horse", "B", 0, 0.75);
    tcb_cmp r;
    tcb_error err = {0};
    assert_int_equal(tcb_compare_cells(&cs.c[0], 1, &cs.c[1], 1, 2000, &r, &err), TCB_OK);
    const tcb_cmp_metric *m = &r.m[TCB_CMP_SL2];
    assert_true(m->has);
    assert_near(m->diff, -0.75, 1e-12);
    assert_near(m->lo, -0.75, 1e-12);
    assert_near(m->hi, -0.75, 1e-12);
    assert_near(m->mean_b - m->mean_a, 0.75, 1e-12);
    /* every difference the same sign, no zero, n = 20 ≤ 50: exact, 2 / 2^20 */
    assert_near(m->p, 2.0 / 1048576.0, 1e-15);
    assert_true(tcb_cmp_significant(m));
    /* AUC: 1 − v·1e-3 → A − B = +0.075 % (×1e2) */
    assert_near(r.m[TCB_CMP_AUC].diff, 0.075, 1e-9);
    assert_false(r.m[TCB_CMP_CD].has);  /* no reconstruction */
    assert_false(r.m[TCB_CMP_GEO].has); /* not scored */
    assert_int_equal(r.n, P);
    assert_true(r.single_seed);
    assert_int_equal(r.resamples, 2000);
}

static void test_identical_methods(void **state)
{
    (void)state;
    cells cs = {.n = 0};
    add(&cs, "horse", "A", 0, 0.5);
    add(&cs, "horse", "B", 0, 0.5);
    tcb_cmp r;
    tcb_error err = {0};
    assert_int_equal(tcb_compare_cells(&cs.c[0], 1, &cs.c[1], 1, 500, &r, &err), TCB_OK);
    assert_near(r.m[TCB_CMP_SL2].diff, 0.0, 0.0);
    assert_near(r.m[TCB_CMP_SL2].lo, 0.0, 0.0);
    assert_true(isnan(r.m[TCB_CMP_SL2].p)); /* every difference 0: no test */
    assert_false(tcb_cmp_significant(&r.m[TCB_CMP_SL2]));
}

/* A's seeds lie c below and c above B on every pair: the estimate is 0, and
 * the seed draws alone give −c (both seeds 0, p = 1/4), 0 (1/2) or +c
 * (1/4): the 2.5 % and 97.5 % quantiles are −c and +c (the pair draws
 * change nothing: the difference is the same on every pair). */
static void test_seed_level(void **state)
{
    (void)state;
    cells cs = {.n = 0};
    add(&cs, "horse", "A", 0, -0.5);
    add(&cs, "horse", "A", 1, 0.5);
    add(&cs, "horse", "B", 0, 0.0);
    tcb_cmp r;
    tcb_error err = {0};
    assert_int_equal(tcb_compare_cells(&cs.c[0], 2, &cs.c[2], 1, 0, &r, &err), TCB_OK);
    assert_int_equal(r.resamples, 10000);
    assert_int_equal(r.seeds_a, 2);
    assert_near(r.m[TCB_CMP_SL2].diff, 0.0, 1e-12);
    assert_near(r.m[TCB_CMP_SL2].lo, -0.5, 1e-12);
    assert_near(r.m[TCB_CMP_SL2].hi, 0.5, 1e-12);
    /* the seed-averaged differences are 0 up to rounding (~1e-15): no
     * difference to speak of, whatever the signs of the rounding say */
    assert_false(tcb_cmp_significant(&r.m[TCB_CMP_SL2]));
}

static void test_other_split_refused(void **state)
{
    (void)state;
    cells cs = {.n = 0};
    add(&cs, "horse", "A", 0, 0.0);
    tcb_cell_result *b = add(&cs, "horse", "B", 0, 1.0);
    tcb_cmp r;
    tcb_error err = {0};
    b->pairs[3].j = 9;
    assert_int_equal(tcb_compare_cells(&cs.c[0], 1, b, 1, 100, &r, &err), TCB_ERR_INPUT);
    assert_non_null(strstr(err.msg, "anim/horse A seed 0 and anim/horse B seed 0 were not scored on the same pairs"));
    b->pairs[3].j = cs.c[0].pairs[3].j;
    b->split_seed = 1;
    assert_int_equal(tcb_compare_cells(&cs.c[0], 1, b, 1, 100, &r, &err), TCB_ERR_INPUT);
    b->split_seed = 0;
    b->status = TCB_CELL_FAILED;
    assert_int_equal(tcb_compare_cells(&cs.c[0], 1, b, 1, 100, &r, &err), TCB_ERR_INPUT);
    assert_non_null(strstr(err.msg, "B seed 0 is failed, not ok"));
}

/* Four sequences, B worse than A by 0.2 on each: the interval is 0.2 and
 * Wilcoxon's exact p with n = 4, all one sign, is 2 / 2^4. */
static void test_means_over_sequences(void **state)
{
    (void)state;
    const double va[4] = {10.0, 12.5, 9.0, 30.0}, vb[4] = {10.2, 12.7, 9.2, 30.2};
    tcb_cmp r;
    memset(&r, 0, sizeof r);
    tcb_error err = {0};
    assert_int_equal(tcb_compare_means(va, vb, 4, TCB_CMP_RANK, 1000, &r, &err), TCB_OK);
    assert_true(r.over_sequences);
    assert_int_equal(r.n, 4);
    assert_near(r.m[TCB_CMP_RANK].diff, -0.2, 1e-12);
    assert_near(r.m[TCB_CMP_RANK].lo, -0.2, 1e-12);
    assert_near(r.m[TCB_CMP_RANK].p, 0.125, 1e-15);
    assert_false(tcb_cmp_significant(&r.m[TCB_CMP_RANK])); /* four sequences cannot */
}

static const tcb_rpt_row *row_of(const tcb_rpt_block *b, const char *method)
{
    for (int k = 0; k < b->n_rows; k++)
        if (!strcmp(b->rows[k].method, method)) return &b->rows[k];
    fail_msg("no row %s", method);
    return NULL;
}

/* horse: A best by a constant on every pair → bold; camel: A and C equal
 * and best → tied, B significantly worse → unmarked. Holm: 3 comparisons
 * per metric, the smallest p × 3. */
static void test_report_marks(void **state)
{
    (void)state;
    cells cs = {.n = 0};
    add(&cs, "camel", "A", 0, 0.0);
    add(&cs, "camel", "B", 0, 1.0);
    add(&cs, "camel", "C", 0, 0.0);
    add(&cs, "horse", "A", 0, 0.0);
    add(&cs, "horse", "B", 0, 1.0);
    add(&cs, "horse", "C", 0, 2.0);
    tcb_rpt r;
    tcb_error err = {0};
    assert_int_equal(tcb_rpt_build(cs.c, cs.n, 500, &r, &err), TCB_OK);
    const tcb_rpt_block *camel = &r.blocks[0], *horse = &r.blocks[1];
    assert_true(horse->compared);
    assert_int_equal(horse->n_cmp, 3);
    assert_true(row_of(horse, "A")->best[TCB_M_SL2]);
    assert_false(row_of(horse, "A")->tie[TCB_M_SL2]);
    assert_false(row_of(horse, "B")->best[TCB_M_SL2] || row_of(horse, "B")->tie[TCB_M_SL2]);
    assert_true(row_of(horse, "A")->best[TCB_M_AUC]); /* higher is better there */
    assert_false(row_of(horse, "A")->best[TCB_M_CD] || row_of(horse, "A")->tie[TCB_M_CD]);
    assert_near(horse->cmp[0].c.m[TCB_M_SL2].p_holm, 3 * 2.0 / 1048576.0, 1e-15);
    assert_true(row_of(camel, "A")->tie[TCB_M_SL2] && row_of(camel, "C")->tie[TCB_M_SL2]);
    assert_false(row_of(camel, "A")->best[TCB_M_SL2] || row_of(camel, "C")->best[TCB_M_SL2]);
    assert_false(row_of(camel, "B")->tie[TCB_M_SL2]);
    /* Holm leaves the no-test comparison (A vs C) out: family of 2 */
    int flip;
    const tcb_rpt_cmp *ab = tcb_rpt_cmp_of(camel, 1, 0, &flip);
    assert_true(flip);
    assert_near(ab->c.m[TCB_M_SL2].p_holm, 2 * 2.0 / 1048576.0, 1e-15);
    /* MEAN over the two test sequences: too few for anything significant */
    const tcb_rpt_block *mean = &r.datasets[0].mean;
    assert_true(mean->compared);
    assert_false(row_of(mean, "A")->best[TCB_M_SL2]);
    assert_true(row_of(mean, "A")->tie[TCB_M_SL2]);
    tcb_rpt_free(&r);
    /* without statistics: the displayed best, as baselines and check see it */
    assert_int_equal(tcb_rpt_build(cs.c, cs.n, TCB_RPT_NO_STATS, &r, &err), TCB_OK);
    assert_false(r.blocks[0].compared);
    assert_true(row_of(&r.blocks[0], "A")->best[TCB_M_SL2] && row_of(&r.blocks[0], "C")->best[TCB_M_SL2]);
    tcb_rpt_free(&r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_constant_difference), cmocka_unit_test(test_identical_methods),
        cmocka_unit_test(test_seed_level),          cmocka_unit_test(test_other_split_refused),
        cmocka_unit_test(test_means_over_sequences), cmocka_unit_test(test_report_marks),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
