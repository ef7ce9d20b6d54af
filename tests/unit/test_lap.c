/* Exact linear assignment: brute force over all permutations (n ≤ 8), a
 * negative-cycle optimality certificate (n up to 120), structured problems
 * with a known unique optimum, degenerate matrices, and the input errors. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "testutil.h"
#include "tcb/lap.h"
#include "tcb/rng.h"

typedef enum {
    K_UNIFORM,   /* [0, 1) */
    K_INT_TIES,  /* integers 0..2: many optimal permutations */
    K_ALL_EQUAL, /* every permutation optimal */
    K_DUP_ROWS,  /* rows copied from a few distinct ones */
    K_DUP_COLS,  /* columns copied from a few distinct ones */
    K_DYNAMIC,   /* each entry 1e-9·U or 1e9·U */
    K_NEGATIVE,  /* [-1000, 1000) */
    K_SQDIST,    /* squared distances between 3-D clouds with duplicated points */
    K_COUNT
} kind;

static const char *kind_name[K_COUNT] = {"uniform", "int-ties", "all-equal", "dup-rows",
                                         "dup-cols", "dynamic", "negative", "sqdist"};

/* Duplicated points: point k of a cloud is drawn from the first ⌈n/3⌉. */
static void fill_sqdist(double *c, int n, tcb_rng *rng)
{
    double p[2][120][3];
    assert_true(n <= 120);
    int distinct = (n + 2) / 3;
    for (int s = 0; s < 2; s++)
        for (int k = 0; k < n; k++) {
            int src = k < distinct ? k : (int)tcb_rng_below(rng, (uint32_t)distinct);
            for (int a = 0; a < 3; a++)
                p[s][k][a] = k < distinct ? tcb_rng_uniform(rng) : p[s][src][a];
        }
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++) {
            double s = 0.0;
            for (int a = 0; a < 3; a++) s += (p[0][i][a] - p[1][j][a]) * (p[0][i][a] - p[1][j][a]);
            c[i * n + j] = s;
        }
}

/* cost [n][n] of the given kind. */
static void fill(double *c, int n, kind k, tcb_rng *rng)
{
    if (k == K_SQDIST) {
        fill_sqdist(c, n, rng);
        return;
    }
    for (int i = 0; i < n * n; i++) {
        double u = tcb_rng_uniform(rng);
        switch (k) {
        case K_INT_TIES: c[i] = (double)tcb_rng_below(rng, 3); break;
        case K_ALL_EQUAL: c[i] = 0.75; break;
        case K_DYNAMIC: c[i] = tcb_rng_below(rng, 2) ? 1e9 * u : 1e-9 * u; break;
        case K_NEGATIVE: c[i] = 2000.0 * u - 1000.0; break;
        default: c[i] = u; break;
        }
    }
    int distinct = (n + 2) / 3; /* rows/columns ≥ distinct copy earlier ones */
    for (int a = distinct; a < n && (k == K_DUP_ROWS || k == K_DUP_COLS); a++) {
        int src = (int)tcb_rng_below(rng, (uint32_t)distinct);
        for (int b = 0; b < n; b++) {
            if (k == K_DUP_ROWS) c[a * n + b] = c[src * n + b];
            else c[b * n + a] = c[b * n + src];
        }
    }
}

/* Total of a permutation, summed in row order as the library does. */
static double perm_total(const double *c, int n, const int32_t *p)
{
    double t = 0.0;
    for (int i = 0; i < n; i++) t += c[i * n + p[i]];
    return t;
}

typedef struct {
    const double *c;
    int n;
    int32_t p[8];
    unsigned used;
    double best, scale; /* least total, and Σ|c| along it */
} brute;

static void brute_rec(brute *b, int row)
{
    if (row == b->n) {
        double t = perm_total(b->c, b->n, b->p);
        if (t < b->best) {
            b->best = t, b->scale = 0.0;
            for (int i = 0; i < b->n; i++) b->scale += fabs(b->c[i * b->n + b->p[i]]);
        }
        return;
    }
    for (int j = 0; j < b->n; j++) {
        if (b->used & (1u << j)) continue;
        b->used |= 1u << j, b->p[row] = j;
        brute_rec(b, row + 1);
        b->used &= ~(1u << j);
    }
}

/* Solves c and checks that the answer is a permutation whose total is the
 * one returned; returns that total. */
static double solve_checked(const double *c, int n, int32_t *sol)
{
    tcb_error err = {0};
    double total = NAN;
    assert_int_equal(tcb_lap_solve(c, n, n, sol, &total, &err), TCB_OK);
    char *seen = calloc((size_t)n, 1);
    assert_non_null(seen);
    for (int i = 0; i < n; i++) {
        assert_true(sol[i] >= 0 && sol[i] < n);
        assert_false(seen[sol[i]]);
        seen[sol[i]] = 1;
    }
    free(seen);
    assert_true(total == perm_total(c, n, sol));
    return total;
}

static void test_brute_force_small(void **state)
{
    (void)state;
    double c[64];
    int32_t sol[8];
    for (int k = 0; k < K_COUNT; k++)
        for (int n = 1; n <= 8; n++)
            for (uint64_t seed = 1; seed <= (n <= 6 ? 40u : 4u); seed++) {
                tcb_rng rng;
                tcb_rng_seed_stream(&rng, seed * 100 + (uint64_t)n, kind_name[k]);
                fill(c, n, (kind)k, &rng);
                double total = solve_checked(c, n, sol);
                brute b = {.c = c, .n = n, .best = INFINITY};
                brute_rec(&b, 0);
                if (!(fabs(total - b.best) <= 1e-12 * b.scale))
                    fail_msg("%s n=%d seed=%d: total %.17g, optimum %.17g", kind_name[k], n,
                             (int)seed, total, b.best);
            }
}

/* An assignment is optimal iff no cycle of rows, each moving to the next
 * one's column, lowers the total: Floyd–Warshall over rows with edge
 * i → i' costing c[i][p(i')] − c[i][p(i)] finds any negative cycle. */
static void assert_no_negative_cycle(const double *c, int n, const int32_t *p, double tol)
{
    double *w = malloc((size_t)n * n * sizeof *w);
    assert_non_null(w);
    for (int i = 0; i < n; i++)
        for (int k = 0; k < n; k++) w[i * n + k] = c[i * n + p[k]] - c[i * n + p[i]];
    for (int m = 0; m < n; m++)
        for (int i = 0; i < n; i++)
            for (int k = 0; k < n; k++)
                w[i * n + k] = fmin(w[i * n + k], w[i * n + m] + w[m * n + k]);
    for (int i = 0; i < n; i++)
        if (w[i * n + i] < -tol) fail_msg("row %d is on a cycle that saves %g", i, -w[i * n + i]);
    free(w);
}

static void test_optimality_certificate(void **state)
{
    (void)state;
    static const int sizes[] = {17, 33, 64, 99, 120};
    double *c = malloc(120 * 120 * sizeof *c);
    int32_t sol[120];
    assert_non_null(c);
    for (int k = 0; k < K_COUNT; k++)
        for (size_t s = 0; s < sizeof sizes / sizeof *sizes; s++) {
            int n = sizes[s];
            tcb_rng rng;
            tcb_rng_seed_stream(&rng, (uint64_t)n, kind_name[k]);
            fill(c, n, (kind)k, &rng);
            solve_checked(c, n, sol);
            double cmax = 0.0;
            for (int i = 0; i < n * n; i++) cmax = fmax(cmax, fabs(c[i]));
            assert_no_negative_cycle(c, n, sol, 1e-12 * n * cmax);
        }
    free(c);
}

/* Zeros on a permuted diagonal, costs in [1, 2) elsewhere: that permutation
 * is the unique optimum, total exactly 0. */
static void test_permuted_zero_diagonal(void **state)
{
    (void)state;
    enum { N = 400 };
    double *c = malloc((size_t)N * N * sizeof *c);
    int32_t perm[N], sol[N];
    assert_non_null(c);
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 3, "test/lap/diagonal");
    tcb_rng_permutation(&rng, perm, N);
    for (int i = 0; i < N * N; i++) c[i] = 1.0 + tcb_rng_uniform(&rng);
    for (int i = 0; i < N; i++) c[i * N + perm[i]] = 0.0;
    assert_true(solve_checked(c, N, sol) == 0.0);
    assert_memory_equal(sol, perm, sizeof perm);
    free(c);
}

static int cmp_index_by(const double *key, int32_t a, int32_t b)
{
    return (key[a] > key[b]) - (key[a] < key[b]);
}

/* Points on a line with cost (a_i − b_j)²: strictly convex, so the unique
 * optimum matches the k-th smallest a to the k-th smallest b. Its augmenting
 * paths are long (every point's partner depends on all the others). */
static void test_sorted_matching_on_a_line(void **state)
{
    (void)state;
    enum { N = 300 };
    double a[N], b[N];
    int32_t ra[N], rb[N], sol[N];
    double *c = malloc((size_t)N * N * sizeof *c);
    assert_non_null(c);
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 5, "test/lap/line");
    for (int i = 0; i < N; i++) a[i] = tcb_rng_uniform(&rng), b[i] = tcb_rng_uniform(&rng);
    for (int i = 0; i < N; i++)
        for (int j = 0; j < N; j++) c[i * N + j] = (a[i] - b[j]) * (a[i] - b[j]);
    /* ra/rb: indices in increasing order of a/b (insertion sort, N small). */
    for (int i = 0; i < N; i++) {
        int k = i;
        for (; k > 0 && cmp_index_by(a, ra[k - 1], i) > 0; k--) ra[k] = ra[k - 1];
        ra[k] = i;
        k = i;
        for (; k > 0 && cmp_index_by(b, rb[k - 1], i) > 0; k--) rb[k] = rb[k - 1];
        rb[k] = i;
    }
    solve_checked(c, N, sol);
    for (int r = 0; r < N; r++) assert_int_equal(sol[ra[r]], rb[r]);
    free(c);
}

/* Ties everywhere at a size where a solver that ends paths on the first
 * column it meets, rather than a free one, would scan O(n²) per path. */
static void test_all_equal_large(void **state)
{
    (void)state;
    enum { N = 1500 };
    double *c = malloc((size_t)N * N * sizeof *c);
    int32_t *sol = malloc(N * sizeof *sol);
    assert_non_null(c);
    assert_non_null(sol);
    for (int i = 0; i < N * N; i++) c[i] = 2.5;
    assert_true(solve_checked(c, N, sol) == 2.5 * N);
    free(c), free(sol);
}

static void test_single_and_total_optional(void **state)
{
    (void)state;
    tcb_error err = {0};
    double c1 = -4.0, total = 0.0;
    int32_t sol[2] = {-1, -1};
    assert_int_equal(tcb_lap_solve(&c1, 1, 1, sol, &total, &err), TCB_OK);
    assert_int_equal(sol[0], 0);
    assert_true(total == -4.0);
    const double c2[4] = {5.0, 1.0, 2.0, 7.0};
    assert_int_equal(tcb_lap_solve(c2, 2, 2, sol, NULL, &err), TCB_OK);
    assert_int_equal(sol[0], 1);
    assert_int_equal(sol[1], 0);
}

static void expect_input_error(const double *c, int rows, int cols, const char *needle)
{
    tcb_error err = {0};
    int32_t sol[16];
    assert_int_equal(tcb_lap_solve(c, rows, cols, sol, NULL, &err), TCB_ERR_INPUT);
    if (!strstr(err.msg, needle)) fail_msg("message '%s' lacks '%s'", err.msg, needle);
}

static void test_errors(void **state)
{
    (void)state;
    double c[12];
    for (int i = 0; i < 12; i++) c[i] = i;
    expect_input_error(c, 3, 4, "3x4");
    expect_input_error(c, 4, 3, "square");
    expect_input_error(c, 0, 0, "empty");
    c[1 * 3 + 2] = NAN;
    expect_input_error(c, 3, 3, "(row 1, col 2)");
    c[1 * 3 + 2] = 0.0, c[2 * 3 + 0] = -INFINITY;
    expect_input_error(c, 3, 3, "(row 2, col 0)");
    c[2 * 3 + 0] = 1e200;
    expect_input_error(c, 3, 3, "(row 2, col 0)");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_brute_force_small),
        cmocka_unit_test(test_optimality_certificate),
        cmocka_unit_test(test_permuted_zero_diagonal),
        cmocka_unit_test(test_sorted_matching_on_a_line),
        cmocka_unit_test(test_all_equal_large),
        cmocka_unit_test(test_single_and_total_optional),
        cmocka_unit_test(test_errors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
