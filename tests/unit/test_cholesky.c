/* meshing/cholesky.c (CHOLMOD) against a dense Cholesky written here in
 * double, on random sparse diagonally dominant matrices given as lower
 * triangles with duplicates; and its refusals. (Against scipy's sparse
 * solve on a mesh's Large-Steps system: test_cholesky_scipy.sh.) */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "tcb/cholesky.h"
#include "tcb/rng.h"

enum { N = 60, K = 3, MAX_E = 8 * N };

typedef struct triplets {
    int n_e, rows[MAX_E], cols[MAX_E];
    double vals[MAX_E], dense[N * N];
} triplets;

static void add(triplets *t, int i, int j, double v)
{
    t->rows[t->n_e] = i;
    t->cols[t->n_e] = j;
    t->vals[t->n_e++] = v;
    t->dense[i * N + j] += v;
    if (i != j) t->dense[j * N + i] += v;
}

/* Off-diagonal entries in (−1, 1), some split into two duplicates, and a
 * diagonal larger than its row's sum of magnitudes: positive definite. */
static void random_spd(tcb_rng *rng, triplets *t)
{
    memset(t, 0, sizeof *t);
    double row_sum[N] = {0};
    for (int e = 0; e < 3 * N; e++) {
        int i = (int)(tcb_rng_uniform(rng) * N), j = (int)(tcb_rng_uniform(rng) * N);
        if (i == j) continue;
        if (i < j) { int s = i; i = j; j = s; }
        double v = 2.0 * tcb_rng_uniform(rng) - 1.0;
        add(t, i, j, 0.5 * v);
        add(t, i, j, 0.5 * v);
        row_sum[i] += fabs(v);
        row_sum[j] += fabs(v);
    }
    for (int i = 0; i < N; i++) add(t, i, i, row_sum[i] + 0.1 + tcb_rng_uniform(rng));
}

/* x = A⁻¹ b by a dense LLᵀ in double, b and x [N][K]. */
static void dense_solve(const double *a, const double *b, double *x)
{
    static double l[N * N];
    memset(l, 0, sizeof l);
    for (int j = 0; j < N; j++) {
        double d = a[j * N + j];
        for (int p = 0; p < j; p++) d -= l[j * N + p] * l[j * N + p];
        l[j * N + j] = sqrt(d);
        for (int i = j + 1; i < N; i++) {
            double s = a[i * N + j];
            for (int p = 0; p < j; p++) s -= l[i * N + p] * l[j * N + p];
            l[i * N + j] = s / l[j * N + j];
        }
    }
    for (int c = 0; c < K; c++) {
        double y[N];
        for (int i = 0; i < N; i++) {
            double s = b[i * K + c];
            for (int p = 0; p < i; p++) s -= l[i * N + p] * y[p];
            y[i] = s / l[i * N + i];
        }
        for (int i = N - 1; i >= 0; i--) {
            double s = y[i];
            for (int p = i + 1; p < N; p++) s -= l[p * N + i] * x[p * K + c];
            x[i * K + c] = s / l[i * N + i];
        }
    }
}

static void test_solve_matches_dense(void **state)
{
    (void)state;
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 3, "cholesky");
    static triplets t;
    for (int trial = 0; trial < 5; trial++) {
        random_spd(&rng, &t);
        tcb_cholesky *f;
        tcb_error err = {0};
        assert_int_equal(tcb_cholesky_factor(N, t.n_e, t.rows, t.cols, t.vals, &f, &err), TCB_OK);
        assert_int_equal(tcb_cholesky_order(f), N);
        double b[N * K], x[N * K], want[N * K];
        for (int i = 0; i < N * K; i++) b[i] = x[i] = 2.0 * tcb_rng_uniform(&rng) - 1.0;
        dense_solve(t.dense, b, want);
        assert_int_equal(tcb_cholesky_solve(f, x, K, &err), TCB_OK);
        for (int i = 0; i < N * K; i++) assert_true(fabs(x[i] - want[i]) <= 1e-12 * (1.0 + fabs(want[i])));
        /* one column alone gives the same bits as the column of three */
        double one[N];
        for (int i = 0; i < N; i++) one[i] = b[i * K + 1];
        assert_int_equal(tcb_cholesky_solve(f, one, 1, &err), TCB_OK);
        for (int i = 0; i < N; i++) assert_true(one[i] == x[i * K + 1]);
        tcb_cholesky_free(f);
    }
}

static void expect_refusal(int n, int n_e, const int *r, const int *c, const double *v, int code, const char *text)
{
    tcb_cholesky *f = (tcb_cholesky *)&f;
    tcb_error err = {0};
    assert_int_equal(tcb_cholesky_factor(n, n_e, r, c, v, &f, &err), code);
    assert_null(f);
    if (!strstr(err.msg, text)) fail_msg("message \"%s\" lacks \"%s\"", err.msg, text);
}

static void test_refusals(void **state)
{
    (void)state;
    int r[] = {0, 1, 1}, c[] = {0, 0, 1};
    double v[] = {1.0, 2.0, 1.0}; /* [[1, 2], [2, 1]]: indefinite */
    expect_refusal(2, 3, r, c, v, TCB_ERR_NUMERIC, "not positive definite");
    int up_r[] = {0, 0, 1}, up_c[] = {0, 1, 1};
    double ok[] = {2.0, 0.5, 2.0};
    expect_refusal(2, 3, up_r, up_c, ok, TCB_ERR_INPUT, "above the diagonal");
    int out_r[] = {0, 2, 1}, out_c[] = {0, 0, 1};
    expect_refusal(2, 3, out_r, out_c, ok, TCB_ERR_INPUT, "entry 1 at (2, 0) of a 2 × 2 matrix");
    double nan_v[] = {2.0, NAN, 2.0};
    expect_refusal(2, 3, r, c, nan_v, TCB_ERR_NUMERIC, "not finite");
    expect_refusal(0, 3, r, c, ok, TCB_ERR_INPUT, "a 0 × 0 matrix");
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_solve_matches_dense), cmocka_unit_test(test_refusals)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
