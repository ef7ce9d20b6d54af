/* Exact nearest neighbours: both backends against an in-test brute force. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "tcb/nn.h"
#include "tcb/rng.h"

/* Same expression as the library: (dx² + dy²) + dz² in float. */
static float ref_d2(const float *p, const float *q)
{
    float s = 0.0f;
    for (int c = 0; c < 3; c++) s += (p[c] - q[c]) * (p[c] - q[c]);
    return s;
}

static void ref_nearest(const float *pts, int n, const float *q, int32_t *idx, float *d2)
{
    *idx = 0;
    *d2 = ref_d2(pts, q);
    for (int j = 1; j < n; j++) {
        float d = ref_d2(pts + 3 * j, q);
        if (d < *d2) *idx = j, *d2 = d;
    }
}

typedef struct {
    float d;
    int32_t j;
} cand;

static int cand_cmp(const void *a, const void *b)
{
    const cand *x = a, *y = b;
    if (x->d != y->d) return x->d < y->d ? -1 : 1;
    return (x->j > y->j) - (x->j < y->j);
}

/* k smallest by (distance, index). */
static void ref_knn(const float *pts, int n, const float *q, int k, int32_t *idx, float *d2)
{
    cand *c = malloc((size_t)n * sizeof *c);
    assert_non_null(c);
    for (int j = 0; j < n; j++) c[j] = (cand){ref_d2(pts + 3 * j, q), j};
    qsort(c, (size_t)n, sizeof *c, cand_cmp);
    for (int a = 0; a < k; a++) idx[a] = c[a].j, d2[a] = c[a].d;
    free(c);
}

static float *random_cloud(int n, uint64_t seed, float lo, float hi)
{
    float *p = malloc((size_t)n * 3 * sizeof(float));
    assert_non_null(p);
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, seed, "test/nn");
    for (int i = 0; i < 3 * n; i++) p[i] = lo + (hi - lo) * (float)tcb_rng_uniform(&rng);
    return p;
}

/* Queries against pts with the given backend; the distance must equal the
 * reference bit for bit, the index too for brute force (and for the kd-tree
 * whenever the reference minimum is unique). */
static void check_query1(const float *pts, int n, const float *qs, int nq, tcb_nn_backend be)
{
    tcb_error err = {0};
    tcb_nn *nn;
    assert_int_equal(tcb_nn_build_backend(pts, n, be, &nn, &err), TCB_OK);
    assert_int_equal(tcb_nn_size(nn), n);
    int32_t *idx = malloc((size_t)nq * sizeof *idx);
    float *d2 = malloc((size_t)nq * sizeof *d2);
    assert_int_equal(tcb_nn_query1(nn, qs, nq, idx, d2, &err), TCB_OK);
    for (int q = 0; q < nq; q++) {
        int32_t ri;
        float rd;
        ref_nearest(pts, n, qs + 3 * q, &ri, &rd);
        assert_true(d2[q] == rd);
        assert_true(ref_d2(pts + 3 * idx[q], qs + 3 * q) == rd);
        if (tcb_nn_backend_of(nn) == TCB_NN_BRUTE) assert_int_equal(idx[q], ri);
    }
    free(idx), free(d2);
    tcb_nn_free(nn);
}

static void check_queryk(const float *pts, int n, const float *qs, int nq, int k,
                         tcb_nn_backend be, int expect_same_index)
{
    tcb_error err = {0};
    tcb_nn *nn;
    assert_int_equal(tcb_nn_build_backend(pts, n, be, &nn, &err), TCB_OK);
    int32_t *idx = malloc((size_t)nq * k * sizeof *idx), *ri = malloc((size_t)k * sizeof *ri);
    float *d2 = malloc((size_t)nq * k * sizeof *d2), *rd = malloc((size_t)k * sizeof *rd);
    assert_int_equal(tcb_nn_queryk(nn, qs, nq, k, idx, d2, &err), TCB_OK);
    for (int q = 0; q < nq; q++) {
        ref_knn(pts, n, qs + 3 * q, k, ri, rd);
        for (int a = 0; a < k; a++) {
            assert_true(d2[q * k + a] == rd[a]);
            if (expect_same_index) assert_int_equal(idx[q * k + a], ri[a]);
            if (a > 0) /* rows ordered by (distance, index) */
                assert_true(d2[q * k + a - 1] < d2[q * k + a] ||
                            (d2[q * k + a - 1] == d2[q * k + a] &&
                             idx[q * k + a - 1] < idx[q * k + a]));
        }
    }
    free(idx), free(ri), free(d2), free(rd);
    tcb_nn_free(nn);
}

static void test_query1_random_both_sides_of_crossover(void **state)
{
    (void)state;
    static const int sizes[] = {1, 2, 7, 8, 9, 100, 1297, 3199, 3200, 3201, 6000};
    for (size_t s = 0; s < sizeof sizes / sizeof *sizes; s++) {
        int n = sizes[s];
        float *pts = random_cloud(n, 10 + s, -1.0f, 1.0f);
        float *qs = random_cloud(300, 100 + s, -1.5f, 1.5f);
        memcpy(qs, pts, 3 * sizeof(float)); /* one query exactly on a point */
        check_query1(pts, n, qs, 300, TCB_NN_AUTO);
        check_query1(pts, n, qs, 300, TCB_NN_BRUTE);
        check_query1(pts, n, qs, 300, TCB_NN_KDTREE);
        free(pts), free(qs);
    }
}

static void test_auto_backend_by_size(void **state)
{
    (void)state;
    tcb_error err = {0};
    tcb_nn *nn;
    float *pts = random_cloud(20000, 1, 0.0f, 1.0f);
    assert_int_equal(tcb_nn_build(pts, 1000, &nn, &err), TCB_OK);
    assert_int_equal(tcb_nn_backend_of(nn), TCB_NN_BRUTE);
    tcb_nn_free(nn);
    assert_int_equal(tcb_nn_build(pts, 20000, &nn, &err), TCB_OK);
    assert_int_equal(tcb_nn_backend_of(nn), TCB_NN_KDTREE);
    tcb_nn_free(nn);
    free(pts);
}

static void test_queryk_random(void **state)
{
    (void)state;
    static const int sizes[] = {1, 5, 64, 1297, 4000};
    static const int ks[] = {1, 3, 16};
    for (size_t s = 0; s < sizeof sizes / sizeof *sizes; s++) {
        int n = sizes[s];
        float *pts = random_cloud(n, 20 + s, 0.0f, 1.0f);
        float *qs = random_cloud(100, 200 + s, -0.2f, 1.2f);
        for (size_t t = 0; t < sizeof ks / sizeof *ks; t++) {
            int k = ks[t] < n ? ks[t] : n;
            /* random coordinates: no ties, so the kd-tree must agree exactly too */
            check_queryk(pts, n, qs, 100, k, TCB_NN_BRUTE, 1);
            check_queryk(pts, n, qs, 100, k, TCB_NN_KDTREE, 1);
            check_queryk(pts, n, qs, 100, k, TCB_NN_AUTO, 1);
        }
        check_queryk(pts, n, qs, 10, n < 50 ? n : 50, TCB_NN_KDTREE, 1);
        free(pts), free(qs);
    }
}

/* Integer lattice, shuffled: a query at a cell centre has 8 equidistant
 * points, one at an edge midpoint 2. Brute force must return the lowest
 * index; the kd-tree one of the tied points with the same distance. */
static void test_ties_lowest_index(void **state)
{
    (void)state;
    enum { G = 6, N = G * G * G };
    float pts[N * 3];
    int32_t perm[N];
    tcb_rng rng;
    tcb_rng_seed(&rng, 5);
    tcb_rng_permutation(&rng, perm, N);
    for (int i = 0; i < N; i++) {
        int c = perm[i];
        pts[3 * i] = (float)(c % G), pts[3 * i + 1] = (float)(c / G % G), pts[3 * i + 2] = (float)(c / (G * G));
    }
    float qs[2 * 3 * 25];
    for (int a = 0; a < 25; a++) {
        float x = (float)(a % 5), y = (float)(a / 5);
        float centre[3] = {x + 0.5f, y + 0.5f, 2.5f}, edge[3] = {x, y + 0.5f, 3.0f};
        memcpy(qs + 6 * a, centre, sizeof centre);
        memcpy(qs + 6 * a + 3, edge, sizeof edge);
    }
    check_query1(pts, N, qs, 50, TCB_NN_BRUTE);
    check_query1(pts, N, qs, 50, TCB_NN_KDTREE);
    check_queryk(pts, N, qs, 50, 8, TCB_NN_BRUTE, 1);
    check_queryk(pts, N, qs, 50, 8, TCB_NN_KDTREE, 0);
}

static void test_single_point(void **state)
{
    (void)state;
    float p[3] = {0.5f, -2.0f, 3.0f};
    float *qs = random_cloud(40, 3, -5.0f, 5.0f);
    check_query1(p, 1, qs, 40, TCB_NN_BRUTE);
    check_query1(p, 1, qs, 40, TCB_NN_KDTREE);
    check_queryk(p, 1, qs, 40, 1, TCB_NN_KDTREE, 1);
    int32_t idx[40];
    tcb_error err = {0};
    assert_int_equal(tcb_nn_nearest(p, 1, qs, 40, idx, NULL, &err), TCB_OK);
    for (int q = 0; q < 40; q++) assert_int_equal(idx[q], 0);
    free(qs);
}

/* Every point duplicated 3×, copies spread over the index range: brute force
 * returns the first copy. */
static void test_duplicate_points(void **state)
{
    (void)state;
    enum { U = 700, N = 3 * U };
    float *base = random_cloud(U, 7, 0.0f, 1.0f);
    float *pts = malloc(N * 3 * sizeof(float));
    for (int c = 0; c < 3; c++) memcpy(pts + 3 * U * c, base, U * 3 * sizeof(float));
    float *qs = random_cloud(200, 8, 0.0f, 1.0f);
    memcpy(qs, base + 3 * 5, 3 * sizeof(float));
    int32_t idx[200];
    float d2[200];
    tcb_error err = {0};
    tcb_nn *nn;
    assert_int_equal(tcb_nn_build_backend(pts, N, TCB_NN_BRUTE, &nn, &err), TCB_OK);
    assert_int_equal(tcb_nn_query1(nn, qs, 200, idx, d2, &err), TCB_OK);
    tcb_nn_free(nn);
    assert_int_equal(idx[0], 5);
    assert_true(d2[0] == 0.0f);
    for (int q = 0; q < 200; q++) assert_in_range(idx[q], 0, U - 1);
    check_query1(pts, N, qs, 200, TCB_NN_KDTREE);
    check_queryk(pts, N, qs, 200, 3, TCB_NN_BRUTE, 1);
    check_queryk(pts, N, qs, 200, 3, TCB_NN_KDTREE, 0);
    free(base), free(pts), free(qs);
}

static void test_deterministic(void **state)
{
    (void)state;
    float *pts = random_cloud(8000, 11, 0.0f, 1.0f), *qs = random_cloud(5000, 12, 0.0f, 1.0f);
    int32_t *a = malloc(5000 * 4 * sizeof *a), *b = malloc(5000 * 4 * sizeof *b);
    tcb_error err = {0};
    for (int be = TCB_NN_BRUTE; be <= TCB_NN_KDTREE; be++) {
        tcb_nn *n1, *n2;
        assert_int_equal(tcb_nn_build_backend(pts, 8000, (tcb_nn_backend)be, &n1, &err), TCB_OK);
        assert_int_equal(tcb_nn_build_backend(pts, 8000, (tcb_nn_backend)be, &n2, &err), TCB_OK);
        assert_int_equal(tcb_nn_queryk(n1, qs, 5000, 4, a, NULL, &err), TCB_OK);
        assert_int_equal(tcb_nn_queryk(n2, qs, 5000, 4, b, NULL, &err), TCB_OK);
        assert_memory_equal(a, b, 5000 * 4 * sizeof *a);
        tcb_nn_free(n1), tcb_nn_free(n2);
    }
    free(pts), free(qs), free(a), free(b);
}

static void test_errors(void **state)
{
    (void)state;
    tcb_error err = {0};
    tcb_nn *nn = (tcb_nn *)(uintptr_t)1; /* must be reset on failure */
    float pts[6] = {0, 0, 0, 1, 1, 1}, q[3] = {0, 0, 0};
    int32_t idx[2];
    assert_int_equal(tcb_nn_build(pts, 0, &nn, &err), TCB_ERR_INPUT);
    assert_null(nn);
    pts[4] = NAN;
    assert_int_equal(tcb_nn_build(pts, 2, &nn, &err), TCB_ERR_NUMERIC);
    assert_non_null(strstr(err.msg, "point 1"));
    pts[4] = 1.0f;
    assert_int_equal(tcb_nn_build(pts, 2, &nn, &err), TCB_OK);
    assert_int_equal(tcb_nn_queryk(nn, q, 1, 0, idx, NULL, &err), TCB_ERR_INPUT);
    assert_int_equal(tcb_nn_queryk(nn, q, 1, 3, idx, NULL, &err), TCB_ERR_INPUT);
    q[2] = INFINITY;
    assert_int_equal(tcb_nn_query1(nn, q, 1, idx, NULL, &err), TCB_ERR_NUMERIC);
    assert_non_null(strstr(err.msg, "query 0"));
    assert_int_equal(tcb_nn_query1(nn, q, 0, idx, NULL, &err), TCB_OK);
    q[2] = -2e18f; /* finite, but its squared distances could overflow */
    assert_int_equal(tcb_nn_query1(nn, q, 1, idx, NULL, &err), TCB_ERR_NUMERIC);
    tcb_nn_free(nn);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_query1_random_both_sides_of_crossover),
        cmocka_unit_test(test_auto_backend_by_size),
        cmocka_unit_test(test_queryk_random),
        cmocka_unit_test(test_ties_lowest_index),
        cmocka_unit_test(test_single_point),
        cmocka_unit_test(test_duplicate_points),
        cmocka_unit_test(test_deterministic),
        cmocka_unit_test(test_errors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
