/* Wilcoxon signed-rank test and Holm's adjustment: exact p-values checked
 * by enumerating every sign pattern (n ≤ 6) and by hand, ties in both
 * branches, zeros switching to the normal approximation, the cases with no
 * test, bad input; Holm on the textbook four-hypothesis example.
 * Agreement with scipy itself is test_wilcoxon_scipy.sh's. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "testutil.h"
#include "tcb/wilcoxon.h"

static tcb_wilcoxon_result run(const double *d, int n)
{
    tcb_wilcoxon_result r;
    tcb_error err = {0};
    assert_int_equal(tcb_wilcoxon(d, n, &r, &err), TCB_OK);
    return r;
}

/* Two-sided p of r+ = observed by brute force: each of the 2^n sign
 * patterns of ranks 1..n is equally likely under H0. */
static double enumerated_p(int n, int observed)
{
    int below = 0, above = 0, total = n * (n + 1) / 2;
    for (unsigned mask = 0; mask < (1u << n); mask++) {
        int sum = 0;
        for (int k = 0; k < n; k++)
            if (mask & (1u << k)) sum += k + 1;
        below += sum <= observed;
        above += sum >= observed;
    }
    if (observed == total / 2) return 1.0;
    double p = 2.0 * (below < above ? below : above) / (double)(1u << n);
    return p > 1.0 ? 1.0 : p;
}

/* Every sign pattern of d = ±1, ±2, …, ±n for n = 1..6. */
static void test_exact_matches_enumeration(void **state)
{
    (void)state;
    for (int n = 1; n <= 6; n++)
        for (unsigned signs = 0; signs < (1u << n); signs++) {
            double d[6];
            int r_plus = 0;
            for (int k = 0; k < n; k++) {
                int positive = (signs >> k) & 1u;
                d[k] = positive ? k + 1 : -(k + 1);
                r_plus += positive ? k + 1 : 0;
            }
            tcb_wilcoxon_result r = run(d, n);
            int r_minus = n * (n + 1) / 2 - r_plus;
            assert_int_equal(r.method, TCB_WILCOXON_EXACT);
            assert_int_equal(r.n_used, n);
            assert_near(r.statistic, r_plus < r_minus ? r_plus : r_minus, 0.0);
            assert_near(r.p, enumerated_p(n, r_plus), 1e-15);
        }
}

/* By hand: all positive gives 2/2^n; n = 5 with r− = 2 counts the subsets
 * {}, {1}, {2}; n = 6 with r− = 3 adds {3}, {1,2}; order does not matter. */
static void test_exact_by_hand(void **state)
{
    (void)state;
    double all_positive[] = {0.3, 1.2, 2.5, 4.0, 5.1, 7.7};
    assert_near(run(all_positive, 6).p, 2.0 / 64.0, 0.0);
    assert_near(run(all_positive, 3).p, 2.0 / 8.0, 0.0);
    double five[] = {5, -2, 3, 1, 4};
    assert_near(run(five, 5).statistic, 2.0, 0.0);
    assert_near(run(five, 5).p, 6.0 / 32.0, 0.0);
    double six[] = {6, 5, -1, 4, -2, 3};
    assert_near(run(six, 6).statistic, 3.0, 0.0);
    assert_near(run(six, 6).p, 10.0 / 64.0, 0.0);
    /* n = 1: r+ ∈ {0, 1}, either tail holds half: p = 1 both ways. */
    double one[] = {-0.5};
    assert_near(run(one, 1).p, 1.0, 0.0);
}

/* Ties without zeros stay exact (scipy): averaged ranks, r+ truncated.
 * {1, −1, 2}: ranks 1.5, 1.5, 3, r+ = 4.5 → 4, P(R ≥ 4) = 3/8 → 0.75. */
static void test_exact_with_ties(void **state)
{
    (void)state;
    double d[] = {1, -1, 2};
    tcb_wilcoxon_result r = run(d, 3);
    assert_int_equal(r.method, TCB_WILCOXON_EXACT);
    assert_near(r.statistic, 1.5, 0.0);
    assert_near(r.p, 0.75, 0.0);
    double all_tied[] = {1, 1, -1};
    r = run(all_tied, 3);
    assert_near(r.statistic, 2.0, 0.0);
    assert_near(r.p, 0.75, 0.0);
}

/* A zero switches to the approximation and is dropped: {0, 1, 2, 3} is
 * n = 3, T = 0, mean 3, variance 3·4·7/24 = 3.5, p = erfc(3/√7)
 * (scipy: 0.10880943004054568). */
static void test_zero_switches_to_normal(void **state)
{
    (void)state;
    double d[] = {0, 1, 2, 3};
    tcb_wilcoxon_result r = run(d, 4);
    assert_int_equal(r.method, TCB_WILCOXON_NORMAL);
    assert_int_equal(r.n_used, 3);
    assert_int_equal(r.n_zero, 1);
    assert_near(r.statistic, 0.0, 0.0);
    assert_near(r.p, 0.10880943004054568, 1e-15);
}

/* n > 50 is approximated; 60 equal differences form one tie group:
 * variance (60·61·121 − ½·60·3599)/24 = 13953.75, T = 0, mean 915
 * (scipy: 9.485737571073745e-15). */
static void test_normal_tie_correction(void **state)
{
    (void)state;
    double d[60];
    for (int i = 0; i < 60; i++) d[i] = 1.0;
    tcb_wilcoxon_result r = run(d, 60);
    assert_int_equal(r.method, TCB_WILCOXON_NORMAL);
    assert_near(r.p, erfc(915.0 / sqrt(13953.75) / sqrt(2.0)), 1e-25);
    assert_near(r.p, 9.485737571073745e-15, 1e-25);
    /* 51 distinct differences: the approximation, not the exact branch. */
    double e[51];
    for (int i = 0; i < 51; i++) e[i] = i % 2 ? i + 1.0 : -(i + 1.0);
    assert_int_equal(run(e, 51).method, TCB_WILCOXON_NORMAL);
    assert_int_equal(run(e, 50).method, TCB_WILCOXON_EXACT);
}

/* scipy returns (nan, nan) for no data and raises for all zeros: no test. */
static void test_no_test(void **state)
{
    (void)state;
    double zeros[] = {0, 0, 0, -0.0};
    tcb_wilcoxon_result r = run(zeros, 4);
    assert_int_equal(r.method, TCB_WILCOXON_NONE);
    assert_true(isnan(r.p) && isnan(r.statistic));
    assert_int_equal(r.n_zero, 4);
    r = run(NULL, 0);
    assert_int_equal(r.method, TCB_WILCOXON_NONE);
    assert_true(isnan(r.p));
}

static void test_rejects_non_finite(void **state)
{
    (void)state;
    double d[] = {1, 2, NAN, 4};
    tcb_wilcoxon_result r;
    tcb_error err = {0};
    assert_int_equal(tcb_wilcoxon(d, 4, &r, &err), TCB_ERR_INPUT);
    assert_non_null(strstr(err.msg, "difference 2 is not finite"));
    d[2] = INFINITY;
    assert_int_equal(tcb_wilcoxon(d, 4, &r, &err), TCB_ERR_INPUT);
}

/* Holm's example (Wikipedia, "Holm–Bonferroni method"): p = 0.01, 0.04,
 * 0.03, 0.005 → sorted ×4, ×3, ×2, ×1 = 0.02, 0.03, 0.06, 0.04; the last
 * is raised to 0.06 by monotonicity. */
static void test_holm_textbook(void **state)
{
    (void)state;
    double p[] = {0.01, 0.04, 0.03, 0.005}, adj[4];
    tcb_error err = {0};
    assert_int_equal(tcb_holm_adjust(p, 4, adj, &err), TCB_OK);
    double want[] = {0.03, 0.06, 0.06, 0.02};
    for (int i = 0; i < 4; i++) assert_near(adj[i], want[i], 1e-15);
    /* capped at 1, in place, ties kept equal */
    double q[] = {0.6, 0.5, 0.5};
    assert_int_equal(tcb_holm_adjust(q, 3, q, &err), TCB_OK);
    for (int i = 0; i < 3; i++) assert_near(q[i], 1.0, 0.0);
    double one[] = {0.2};
    assert_int_equal(tcb_holm_adjust(one, 1, one, &err), TCB_OK);
    assert_near(one[0], 0.2, 0.0);
}

static void test_holm_rejects_bad_p(void **state)
{
    (void)state;
    double p[] = {0.1, 1.5}, adj[2];
    tcb_error err = {0};
    assert_int_equal(tcb_holm_adjust(p, 2, adj, &err), TCB_ERR_INPUT);
    assert_non_null(strstr(err.msg, "p-value 1 is not in [0, 1]"));
    p[1] = NAN;
    assert_int_equal(tcb_holm_adjust(p, 2, adj, &err), TCB_ERR_INPUT);
}

/* The smallest p is the exact test's p of n differences of one sign, and
 * first falls under 0.05 at n = 6. */
static void test_smallest_p(void **state)
{
    (void)state;
    double d[8] = {1, 2, 3, 4, 5, 6, 7, 8};
    for (int n = 1; n <= 8; n++) {
        tcb_wilcoxon_result w;
        tcb_error err = {0};
        assert_int_equal(tcb_wilcoxon(d, n, &w, &err), TCB_OK);
        assert_true(w.method == TCB_WILCOXON_EXACT);
        assert_true(tcb_wilcoxon_smallest_p(n) == w.p);
    }
    assert_true(tcb_wilcoxon_smallest_p(5) >= 0.05 && tcb_wilcoxon_smallest_p(6) < 0.05);
    assert_true(tcb_wilcoxon_smallest_p(0) == 1.0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_exact_matches_enumeration),
        cmocka_unit_test(test_exact_by_hand),
        cmocka_unit_test(test_smallest_p),
        cmocka_unit_test(test_exact_with_ties),
        cmocka_unit_test(test_zero_switches_to_normal),
        cmocka_unit_test(test_normal_tie_correction),
        cmocka_unit_test(test_no_test),
        cmocka_unit_test(test_rejects_non_finite),
        cmocka_unit_test(test_holm_textbook),
        cmocka_unit_test(test_holm_rejects_bad_p),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
