/* The seeded hierarchical paired bootstrap: reproducible per seed, exact on
 * a constant difference, the estimate equal to the direct computation, the
 * draw order as documented, the input errors, and the coverage of its 95 %
 * interval on synthetic problems with a known mean difference. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>

#include "testutil.h"
#include "tcb/bootstrap.h"
#include "tcb/rng.h"

enum { SA = 3, SB = 2, P = 40 };

/* x[s][p] = base_p + offset + seed noise, from a fixed stream. */
static void fill(double *x, int seeds, int pairs, double offset, uint64_t seed)
{
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, seed, "test_bootstrap/fill");
    for (int s = 0; s < seeds; s++)
        for (int p = 0; p < pairs; p++)
            x[s * pairs + p] = 10.0 + (double)(p % 7) + offset + 0.5 * tcb_rng_normal(&rng);
}

static void test_reproducible(void **state)
{
    (void)state;
    double xa[SA * P], xb[SB * P];
    fill(xa, SA, P, 0.3, 1);
    fill(xb, SB, P, 0.0, 2);
    tcb_boot_result r1, r2, r3;
    tcb_error err = {0};
    assert_int_equal(tcb_bootstrap_paired(xa, SA, xb, SB, P, 7, "cat", 0, NULL, &r1, &err), TCB_OK);
    assert_int_equal(tcb_bootstrap_paired(xa, SA, xb, SB, P, 7, "cat", 0, NULL, &r2, &err), TCB_OK);
    assert_int_equal(tcb_bootstrap_paired(xa, SA, xb, SB, P, 8, "cat", 0, NULL, &r3, &err), TCB_OK);
    assert_int_equal(r1.resamples, TCB_BOOT_RESAMPLES);
    assert_true(r1.lo == r2.lo && r1.hi == r2.hi);
    assert_true(r1.lo != r3.lo && r1.hi != r3.hi);
    assert_true(r1.estimate == r3.estimate);
    assert_true(r1.lo < r1.estimate && r1.estimate < r1.hi);
}

static void test_constant_difference(void **state)
{
    (void)state;
    double xa[SA * P], xb[SB * P];
    for (int p = 0; p < P; p++) {
        for (int s = 0; s < SA; s++) xa[s * P + p] = 2.25 + p;
        for (int s = 0; s < SB; s++) xb[s * P + p] = 1.0 + p;
    }
    tcb_boot_result r;
    tcb_error err = {0};
    assert_int_equal(tcb_bootstrap_paired(xa, SA, xb, SB, P, 0, "c", 2000, NULL, &r, &err), TCB_OK);
    assert_near(r.estimate, 1.25, 1e-12);
    assert_near(r.lo, 1.25, 1e-12);
    assert_near(r.hi, 1.25, 1e-12);
}

/* The estimate is mean_p(mean_s xa − mean_s xb), computed here directly;
 * and each resample's draws lie in range, in the documented order. */
static void test_estimate_and_draws(void **state)
{
    (void)state;
    double xa[SA * P], xb[SB * P];
    fill(xa, SA, P, 1.5, 3);
    fill(xb, SB, P, 0.0, 4);
    double direct = 0.0;
    for (int p = 0; p < P; p++) {
        double a = (xa[p] + xa[P + p] + xa[2 * P + p]) / 3.0, b = (xb[p] + xb[P + p]) / 2.0;
        direct += a - b;
    }
    direct /= P;
    enum { R = 50, PER = SA + SB + P };
    int32_t draws[R * PER];
    tcb_boot_result r;
    tcb_error err = {0};
    assert_int_equal(tcb_bootstrap_paired(xa, SA, xb, SB, P, 5, "d", R, draws, &r, &err), TCB_OK);
    assert_near(r.estimate, direct, 1e-12);
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 5, "d");
    for (int i = 0; i < R * PER; i++) {
        int k = i % PER, n = k < SA ? SA : k < SA + SB ? SB : P;
        assert_int_equal(draws[i], (int32_t)tcb_rng_below(&rng, (uint32_t)n));
    }
}

/* Across sequences: one value per sequence and method, the sequences the
 * resampled units; the estimate is the mean of the per-sequence differences. */
static void test_across_sequences(void **state)
{
    (void)state;
    const double a[6] = {61.44, 12.5, 30.0, 8.25, 19.0, 44.0}, b[6] = {60.24, 12.0, 31.0, 8.0, 18.5, 43.0};
    tcb_boot_result r;
    tcb_error err = {0};
    assert_int_equal(tcb_bootstrap_paired(a, 1, b, 1, 6, 0, "mean", 0, NULL, &r, &err), TCB_OK);
    assert_near(r.estimate, (1.2 + 0.5 - 1.0 + 0.25 + 0.5 + 1.0) / 6, 1e-12);
    /* the resample means lie between the least and the largest difference */
    assert_true(-1.0 <= r.lo && r.lo < r.estimate && r.estimate < r.hi && r.hi <= 1.2 + 1e-12);
}

static void test_quantile_linear(void **state)
{
    (void)state;
    const double v[5] = {1, 2, 4, 8, 16};
    /* np.percentile([1,2,4,8,16], [0, 2.5, 50, 97.5, 100]) */
    assert_near(tcb_quantile_sorted(v, 5, 0.0), 1.0, 0);
    assert_near(tcb_quantile_sorted(v, 5, 0.025), 1.1, 1e-15);
    assert_near(tcb_quantile_sorted(v, 5, 0.5), 4.0, 0);
    assert_near(tcb_quantile_sorted(v, 5, 0.975), 15.2, 1e-14);
    assert_near(tcb_quantile_sorted(v, 5, 1.0), 16.0, 0);
}

static void test_bad_input(void **state)
{
    (void)state;
    double xa[2] = {1, NAN}, xb[2] = {0, 0};
    tcb_boot_result r;
    tcb_error err = {0};
    assert_int_equal(tcb_bootstrap_paired(xa, 1, xb, 1, 2, 0, "e", 10, NULL, &r, &err), TCB_ERR_INPUT);
    assert_string_equal(err.msg, "bootstrap: method A, seed 0, pair 1 is not finite");
    assert_int_equal(tcb_bootstrap_paired(xb, 1, xb, 0, 2, 0, "e", 10, NULL, &r, &err), TCB_ERR_INPUT);
    assert_int_equal(tcb_bootstrap_paired(xb, 1, xb, 1, 2, 0, "e", -1, NULL, &r, &err), TCB_ERR_INPUT);
}

/* Coverage: N_PROBLEMS problems of COV_P paired differences N(μ, 1), one
 * seed per method; the 95 % interval must hold μ in 93–97 % of them
 * (measured 93.85 %: the percentile interval under-covers a little at
 * P = 50, see tcb/bootstrap.h). */
enum { N_PROBLEMS = 2000, COV_P = 50, COV_R = 2000 };

static void test_coverage(void **state)
{
    (void)state;
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 0, "test_bootstrap/coverage");
    double xa[COV_P], xb[COV_P];
    const double mu = 0.7;
    int hits = 0;
    for (int t = 0; t < N_PROBLEMS; t++) {
        for (int p = 0; p < COV_P; p++) {
            xb[p] = 5.0 + tcb_rng_normal(&rng);
            xa[p] = xb[p] + mu + tcb_rng_normal(&rng);
        }
        tcb_boot_result r;
        tcb_error err = {0};
        assert_int_equal(tcb_bootstrap_paired(xa, 1, xb, 1, COV_P, (uint64_t)t, "cov", COV_R, NULL, &r, &err),
                         TCB_OK);
        hits += r.lo <= mu && mu <= r.hi;
    }
    double coverage = (double)hits / N_PROBLEMS;
    print_message("coverage of the 95 %% interval: %.4f (%d problems, P %d, %d resamples)\n", coverage,
                  N_PROBLEMS, COV_P, COV_R);
    assert_true(coverage >= 0.93 && coverage <= 0.97);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_reproducible),     cmocka_unit_test(test_constant_difference),
        cmocka_unit_test(test_estimate_and_draws), cmocka_unit_test(test_across_sequences),
        cmocka_unit_test(test_quantile_linear),
        cmocka_unit_test(test_bad_input),        cmocka_unit_test(test_coverage),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
