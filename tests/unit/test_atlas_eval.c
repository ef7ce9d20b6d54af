/* Atlas evaluation helpers: the regular UV points (against a literal
 * brute-force transcription of the protocol's algorithm, plus spacing and
 * edge cases) and the collapsed-patch rule on synthetic tangents. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "methods/atlas/collapse.h"
#include "methods/atlas/uv_regular.h"
#include "tcb/rng.h"
#include "testutil.h"

/* ---- regular UV points -------------------------------------------------- */

/* reference-protocol §5.3 item 4 word for word, brute force, drawing from
 * the rng in the library's order (x_i, y_i per point, then one angle per
 * point per iteration). */
static void literal_regular(int m, tcb_rng *rng, double *x)
{
    double *c = malloc((size_t)m * 2 * sizeof *c), *d = malloc((size_t)m * 2 * sizeof *d);
    assert_true(c && d);
    for (int i = 0; i < 2 * m; i++) x[i] = tcb_rng_uniform(rng);
    double step = 0.25 / sqrt(m);
    for (int it = 0; it < 250; it++) {
        for (int i = 0; i < m; i++) {
            double a = 2 * M_PI * tcb_rng_uniform(rng);
            c[2 * i] = fmin(fmax(x[2 * i] + step * cos(a), 0), 1);
            c[2 * i + 1] = fmin(fmax(x[2 * i + 1] + step * sin(a), 0), 1);
        }
        for (int i = 0; i < m; i++) {
            d[2 * i] = d[2 * i + 1] = INFINITY;
            for (int j = 0; j < m; j++) {
                if (j == i) continue;
                double dx = x[2 * j] - x[2 * i], dy = x[2 * j + 1] - x[2 * i + 1];
                double cx = c[2 * j] - c[2 * i], cy = c[2 * j + 1] - c[2 * i + 1];
                d[2 * i] = fmin(d[2 * i], dx * dx + dy * dy);
                d[2 * i + 1] = fmin(d[2 * i + 1], cx * cx + cy * cy);
            }
        }
        for (int i = 0; i < m; i++)
            if (d[2 * i + 1] > d[2 * i]) x[2 * i] = c[2 * i], x[2 * i + 1] = c[2 * i + 1];
        step *= 0.994;
    }
    free(c), free(d);
}

static float *regular(int m, uint64_t seed)
{
    float *uv = malloc((size_t)m * 2 * sizeof *uv);
    assert_non_null(uv);
    tcb_rng rng;
    tcb_rng_seed(&rng, seed);
    tcb_error err = {0};
    assert_int_equal(tcb_atlas_uv_regular(m, &rng, uv, &err), TCB_OK);
    return uv;
}

static double min_dist(const float *uv, int m)
{
    double best = INFINITY;
    for (int i = 0; i < m; i++)
        for (int j = i + 1; j < m; j++) {
            double dx = uv[2 * i] - uv[2 * j], dy = uv[2 * i + 1] - uv[2 * j + 1];
            best = fmin(best, dx * dx + dy * dy);
        }
    return sqrt(best);
}

static void test_uv_matches_literal_algorithm(void **state)
{
    (void)state;
    static const int sizes[] = {3, 40, 300};
    for (int k = 0; k < 3; k++) {
        int m = sizes[k];
        float *uv = regular(m, 11);
        double *want = malloc((size_t)m * 2 * sizeof *want);
        assert_non_null(want);
        tcb_rng rng;
        tcb_rng_seed(&rng, 11);
        literal_regular(m, &rng, want);
        for (int i = 0; i < 2 * m; i++) assert_true(uv[i] == (float)want[i]);
        free(uv), free(want);
    }
}

/* Spacing: on 312 points (the protocol's first pass) the annealed set's
 * minimum distance was 0.68–0.89/√m over seeds and sizes 312–3125, against
 * 0.006–0.05/√m for i.i.d. uniform points. Bounds asserted: ≥ 0.5/√m, and
 * ≥ 10× the minimum distance of the i.i.d. start, which is the first 2m
 * draws of the same stream. */
static void test_uv_spacing(void **state)
{
    (void)state;
    const int m = 312;
    float *uv = regular(m, 12), *iid = malloc((size_t)m * 2 * sizeof *iid);
    assert_non_null(iid);
    tcb_rng rng;
    tcb_rng_seed(&rng, 12);
    for (int i = 0; i < 2 * m; i++) iid[i] = (float)tcb_rng_uniform(&rng);
    for (int i = 0; i < 2 * m; i++) assert_true(uv[i] >= 0.0f && uv[i] <= 1.0f);
    double reg = min_dist(uv, m), start = min_dist(iid, m);
    if (!(reg >= 0.5 / sqrt(m) && reg >= 10 * start))
        fail_msg("min distance %g (i.i.d. start %g, 0.5/sqrt(m) = %g)", reg, start,
                 0.5 / sqrt(m));
    free(uv), free(iid);
}

static void test_uv_deterministic(void **state)
{
    (void)state;
    float *a = regular(100, 7), *b = regular(100, 7), *c = regular(100, 8);
    assert_memory_equal(a, b, 200 * sizeof *a);
    assert_memory_not_equal(a, c, 200 * sizeof *a);
    free(a), free(b), free(c);
}

/* One point has no neighbour, so it never moves from its draw; two points
 * end at opposite corners (distance √2 in every run measured). */
static void test_uv_one_and_two_points(void **state)
{
    (void)state;
    float *one = regular(1, 3);
    tcb_rng rng;
    tcb_rng_seed(&rng, 3);
    assert_true(one[0] == (float)tcb_rng_uniform(&rng));
    assert_true(one[1] == (float)tcb_rng_uniform(&rng));
    free(one);
    for (uint64_t seed = 0; seed < 4; seed++) {
        float *two = regular(2, seed);
        for (int i = 0; i < 4; i++) assert_true(two[i] >= 0.0f && two[i] <= 1.0f);
        assert_true(min_dist(two, 2) > 1.4);
        free(two);
    }
    float uv[2];
    tcb_error err = {0};
    assert_int_equal(tcb_atlas_uv_regular(0, &rng, uv, &err), TCB_ERR_INPUT);
}

/* A set is made once per m and does not depend on the order of requests. */
static void test_uv_cache(void **state)
{
    (void)state;
    tcb_atlas_uv_cache a, b;
    tcb_atlas_uv_cache_init(&a, 5);
    tcb_atlas_uv_cache_init(&b, 5);
    tcb_error err = {0};
    const float *a40, *a41, *again, *b40, *b41;
    assert_int_equal(tcb_atlas_uv_cache_get(&a, 40, &a40, &err), TCB_OK);
    assert_int_equal(tcb_atlas_uv_cache_get(&a, 41, &a41, &err), TCB_OK);
    assert_int_equal(tcb_atlas_uv_cache_get(&a, 40, &again, &err), TCB_OK);
    assert_ptr_equal(a40, again);
    assert_int_equal(tcb_atlas_uv_cache_get(&b, 41, &b41, &err), TCB_OK);
    assert_int_equal(tcb_atlas_uv_cache_get(&b, 40, &b40, &err), TCB_OK);
    assert_memory_equal(a40, b40, 80 * sizeof *a40);
    assert_memory_equal(a41, b41, 82 * sizeof *a41);
    for (int m = 1; m <= 6; m++) /* grows past its first allocation */
        assert_int_equal(tcb_atlas_uv_cache_get(&a, m, &again, &err), TCB_OK);
    assert_int_equal(tcb_atlas_uv_cache_get(&a, 0, &again, &err), TCB_ERR_INPUT);
    tcb_atlas_uv_cache_free(&a);
    tcb_atlas_uv_cache_free(&b);
}

/* ---- collapsed patches ---------------------------------------------------- */

enum { S = 2, P = 4, PER = 3, M = P * PER };

/* Every sample of patch p of shape s gets φ_u = (a, 0, 0) and φ_v = (0, a, 0)
 * (EG − F² = a⁴), or φ_v = φ_u (EG − F² = 0) when a < 0. */
static void set_patch(float *pu, float *pv, int s, int p, float a)
{
    for (int k = 0; k < PER; k++) {
        size_t i = ((size_t)s * M + (size_t)p * PER + k) * 3;
        float v = fabsf(a);
        pu[i] = v, pu[i + 1] = 0, pu[i + 2] = 0;
        pv[i] = a < 0 ? v : 0, pv[i + 1] = a < 0 ? 0 : v, pv[i + 2] = 0;
    }
}

static void healthy(float *pu, float *pv)
{
    for (int s = 0; s < S; s++)
        for (int p = 0; p < P; p++) set_patch(pu, pv, s, p, 1.0f);
}

static void expect_kept(const float *pu, const float *pv, const int *want, int n_want)
{
    int kept[P], n = -1, m = -1;
    tcb_error err = {0};
    assert_int_equal(tcb_atlas_kept_patches(pu, pv, S, M, P, 3125, kept, &n, &m, &err), TCB_OK);
    assert_int_equal(n, n_want);
    for (int k = 0; k < n; k++) assert_int_equal(kept[k], want[k]);
    assert_int_equal(m, 3125 / n_want);
}

static void test_collapse_union_over_pair(void **state)
{
    (void)state;
    float pu[S * M * 3], pv[S * M * 3];
    const int all[] = {0, 1, 2, 3}, without2[] = {0, 1, 3};

    healthy(pu, pv);
    expect_kept(pu, pv, all, 4); /* m' = 781 */

    set_patch(pu, pv, 0, 1, -1.0f); /* degenerate in shape 0 only: kept */
    expect_kept(pu, pv, all, 4);

    set_patch(pu, pv, 0, 2, -1.0f); /* degenerate in both: dropped, m' = 1041 */
    set_patch(pu, pv, 1, 2, -1.0f);
    expect_kept(pu, pv, without2, 3);

    for (int s = 0; s < S; s++) /* all degenerate: all kept */
        for (int p = 0; p < P; p++) set_patch(pu, pv, s, p, -1.0f);
    expect_kept(pu, pv, all, 4);
}

/* The threshold is on the mean SQUARED area element relative to the mean
 * over patches: with patch 3 scaled by a (Ap = a⁴, the others 1) the ratio
 * is 4a⁴/(3 + a⁴), which crosses 1e-3 between a⁴ = 1e-3 (kept) and
 * a⁴ = 5e-4 (dropped). Thresholding the area A = a² instead would keep both. */
static void test_collapse_threshold(void **state)
{
    (void)state;
    float pu[S * M * 3], pv[S * M * 3];
    const int all[] = {0, 1, 2, 3}, first3[] = {0, 1, 2};
    healthy(pu, pv);
    for (int s = 0; s < S; s++) set_patch(pu, pv, s, 3, (float)pow(1e-3, 0.25));
    expect_kept(pu, pv, all, 4);
    for (int s = 0; s < S; s++) set_patch(pu, pv, s, 3, (float)pow(5e-4, 0.25));
    expect_kept(pu, pv, first3, 3);
}

static void test_collapse_sizes(void **state)
{
    (void)state;
    enum { P10 = 10, M10 = 10 * 2 };
    float pu[M10 * 3] = {0}, pv[M10 * 3] = {0};
    for (int k = 0; k < M10; k++) pu[3 * k] = 1, pv[3 * k + 1] = 1;
    pu[0] = pv[1] = pu[3] = pv[4] = 0; /* patch 0 of the only shape */
    int kept[P10], n, m;
    tcb_error err = {0};
    assert_int_equal(tcb_atlas_kept_patches(pu, pv, 1, M10, P10, 3125, kept, &n, &m, &err),
                     TCB_OK);
    assert_int_equal(n, 9);
    assert_int_equal(kept[0], 1);
    assert_int_equal(m, 347); /* the protocol's 9 × 347 = 3123 */
    assert_int_equal(tcb_atlas_kept_patches(pu, pv, 1, M10, 3, 3125, kept, &n, &m, &err),
                     TCB_ERR_INPUT); /* 20 samples do not split into 3 patches */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_uv_matches_literal_algorithm),
        cmocka_unit_test(test_uv_spacing),
        cmocka_unit_test(test_uv_deterministic),
        cmocka_unit_test(test_uv_one_and_two_points),
        cmocka_unit_test(test_uv_cache),
        cmocka_unit_test(test_collapse_union_over_pair),
        cmocka_unit_test(test_collapse_threshold),
        cmocka_unit_test(test_collapse_sizes),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
