/* CC triplet samplers (methods/cycle/triplets.h): the knn graph against a
 * naive double-precision Chamfer written here from NN_metric's formula, the
 * row order (A first, ties to the lower index, k clipped), the three
 * samplers' supports and uniformity, reproducibility, and the errors. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "methods/cycle/triplets.h"
#include "tcb/nn.h"
#include "tcb/rng.h"
#include "tcb/sequence.h"
#include "testutil.h"

/* ---- synthetic sequences ------------------------------------------------ */

/* A sequence with n_frames frames and pools of pool_size points, pools
 * uninitialised (the caller fills them); one dummy vertex and face. */
static void make_seq(tcb_sequence *s, const char *name, int n_frames, int pool_size)
{
    tcb_error err = {0};
    if (tcb_sequence_alloc(s, name, n_frames, 1, 1, &err)) fail_msg("alloc: %s", err.msg);
    memset(s->verts, 0, 3 * sizeof(float) * (size_t)n_frames);
    memset(s->faces, 0, 3 * sizeof(int32_t));
    s->pool_size = pool_size;
    s->pools = malloc(sizeof(float) * 3 * (size_t)n_frames * (size_t)pool_size);
    assert_non_null(s->pools);
}

static float *pool(tcb_sequence *s, int f) { return s->pools + (size_t)f * s->pool_size * 3; }

/* Frame f: a random cloud in an anisotropic box, bent and stretched by an
 * f-dependent warp, so frames differ by non-rigid, non-monotone amounts. */
static void fill_warped(tcb_sequence *s, uint64_t seed)
{
    tcb_rng r;
    tcb_rng_seed(&r, seed);
    for (int f = 0; f < s->n_frames; f++) {
        double ph = 0.9 * f;
        for (int i = 0; i < s->pool_size; i++) {
            float *p = pool(s, f) + 3 * i;
            double x = tcb_rng_uniform(&r) - 0.5, y = 2.0 * tcb_rng_uniform(&r) - 1.0,
                   z = 0.6 * tcb_rng_uniform(&r);
            p[0] = (float)(x * (1.0 + 0.3 * sin(ph)) + 0.2 * y * y * cos(2 * ph));
            p[1] = (float)(y + 0.1 * f);
            p[2] = (float)(z + 0.25 * x * sin(ph + 1.0));
        }
    }
}

/* ---- the reference: NN_metric in double --------------------------------- */

static double min_d2(const double *q, const double *set, int n)
{
    double best = INFINITY;
    for (int j = 0; j < n; j++) {
        const double *p = set + 3 * j;
        double d = (q[0] - p[0]) * (q[0] - p[0]) + (q[1] - p[1]) * (q[1] - p[1]) +
                   (q[2] - p[2]) * (q[2] - p[2]);
        if (d < best) best = d;
    }
    return best;
}

static double ref_chamfer(const double *P, const double *Q, int m)
{
    double s1 = 0.0, s2 = 0.0;
    for (int i = 0; i < m; i++) s1 += min_d2(P + 3 * i, Q, m);
    for (int i = 0; i < m; i++) s2 += min_d2(Q + 3 * i, P, m);
    return s1 / m + s2 / m;
}

/* The first m pool points of frame f in double, optionally in the frame's
 * bounding box (centre the bbox of the WHOLE pool, divide by the largest
 * half-extent), as normalize_points.BoundingBox. */
static void ref_subset(const tcb_sequence *s, int f, int m, int in_box, double *out)
{
    const float *p = tcb_seq_pool(s, f);
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int i = 0; i < s->pool_size; i++)
        for (int d = 0; d < 3; d++) lo[d] = fmin(lo[d], p[3 * i + d]), hi[d] = fmax(hi[d], p[3 * i + d]);
    double c[3] = {0, 0, 0}, scale = 1.0;
    if (in_box) {
        scale = 0.0;
        for (int d = 0; d < 3; d++) c[d] = 0.5 * (lo[d] + hi[d]), scale = fmax(scale, 0.5 * (hi[d] - lo[d]));
    }
    for (int i = 0; i < 3 * m; i++) out[i] = (p[i] - c[i % 3]) / scale;
}

static void ref_matrix(const tcb_sequence *s, int m, int in_box, double *D)
{
    const int n = s->n_frames;
    double *sub = malloc(sizeof(double) * 3 * (size_t)m * n);
    assert_non_null(sub);
    for (int f = 0; f < n; f++) ref_subset(s, f, m, in_box, sub + (size_t)f * 3 * m);
    for (int a = 0; a < n; a++)
        for (int b = 0; b < n; b++)
            D[a * n + b] = a == b ? 0.0 : ref_chamfer(sub + (size_t)a * 3 * m, sub + (size_t)b * 3 * m, m);
    free(sub);
}

static tcb_cc_sampler *make_sampler(const tcb_sequence *s, tcb_cc_sampling mode, int k,
                                    int points, int in_box, int delta)
{
    tcb_cc_sampler_opts o = tcb_cc_sampler_opts_default();
    o.sampling = mode, o.knn_k = k, o.knn_points = points, o.knn_in_box = in_box, o.delta = delta;
    tcb_cc_sampler *smp = NULL;
    tcb_error err = {0};
    if (tcb_cc_sampler_create(s, &o, &smp, &err)) fail_msg("create: %s", err.msg);
    assert_non_null(smp);
    return smp;
}

/* ---- the knn graph ------------------------------------------------------ */

static void test_parse(void **state)
{
    (void)state;
    static const char *const names[] = {"random", "knn", "neighbors"};
    for (int m = 0; m < 3; m++) {
        tcb_cc_sampling s = (tcb_cc_sampling)-1;
        tcb_error err = {0};
        assert_int_equal(tcb_cc_sampling_parse(names[m], &s, &err), TCB_OK);
        assert_int_equal((int)s, m);
        assert_string_equal(tcb_cc_sampling_name(s), names[m]);
    }
    assert_null(tcb_cc_sampling_name((tcb_cc_sampling)3));
    static const char *const bad[] = {"knnn", "Random", "", "neighbours"};
    for (int b = 0; b < 4; b++) {
        tcb_cc_sampling s = TCB_CC_SAMPLE_KNN;
        tcb_error err = {0};
        assert_int_equal(tcb_cc_sampling_parse(bad[b], &s, &err), TCB_ERR_INPUT);
        char quoted[64];
        snprintf(quoted, sizeof quoted, "'%s'", bad[b]);
        if (!strstr(err.msg, quoted)) fail_msg("'%s' does not name %s", err.msg, quoted);
        assert_int_equal((int)s, TCB_CC_SAMPLE_KNN); /* untouched */
    }
    tcb_cc_sampling s;
    tcb_error err = {0};
    assert_int_equal(tcb_cc_sampling_parse(NULL, &s, &err), TCB_ERR_INPUT);
}

/* D against the naive Chamfer, raw and in the CC boxes; the subset is the
 * pool's first `points` points (the pool is longer). Relative 1e-5: the
 * library's squared distances are float. */
static void test_distances_match_reference(void **state)
{
    (void)state;
    enum { F = 7, POOL = 300, M = 170 };
    tcb_sequence s;
    make_seq(&s, "warp", F, POOL);
    fill_warped(&s, 11);
    double D[F * F], R[F * F];
    for (int in_box = 0; in_box < 2; in_box++) {
        tcb_error err = {0};
        assert_int_equal(tcb_cc_frame_distances(&s, M, in_box, D, &err), TCB_OK);
        ref_matrix(&s, M, in_box, R);
        for (int a = 0; a < F; a++)
            for (int b = 0; b < F; b++) {
                assert_true(D[a * F + b] == D[b * F + a]);
                if (a == b) assert_true(D[a * F + b] == 0.0);
                else assert_near(D[a * F + b], R[a * F + b], 1e-5 * R[a * F + b]);
            }
        /* boxes matter: the raw and boxed distances differ */
        if (in_box) {
            double raw[F * F];
            assert_int_equal(tcb_cc_frame_distances(&s, M, 0, raw, &err), TCB_OK);
            assert_true(fabs(raw[1] - D[1]) > 1e-3 * D[1]);
        }
    }
    /* bit for bit what serial tcb_nn queries give (the library computes
     * rows in parallel; the result must not depend on that) */
    {
        tcb_error e = {0};
        assert_int_equal(tcb_cc_frame_distances(&s, M, 0, D, &e), TCB_OK);
        float d2[M];
        int32_t idx[M];
        for (int a = 0; a < F; a++)
            for (int b = 0; b < F; b++) {
                if (a == b) continue;
                double sum[2];
                for (int dir = 0; dir < 2; dir++) {
                    const float *q = pool(&s, dir ? b : a), *p = pool(&s, dir ? a : b);
                    assert_int_equal(tcb_nn_nearest(p, M, q, M, idx, d2, &e), TCB_OK);
                    sum[dir] = 0.0;
                    for (int i = 0; i < M; i++) sum[dir] += d2[i];
                }
                double expect = a < b ? sum[0] / M + sum[1] / M : sum[1] / M + sum[0] / M;
                if (D[a * F + b] != expect)
                    fail_msg("D[%d][%d] = %.17g, serial tcb_nn %.17g", a, b, D[a * F + b], expect);
            }
    }
    /* points beyond the pool are clipped to the pool */
    tcb_error err = {0};
    assert_int_equal(tcb_cc_frame_distances(&s, 100000, 0, D, &err), TCB_OK);
    ref_matrix(&s, POOL, 0, R);
    for (int i = 0; i < F * F; i++) assert_near(D[i], R[i], 1e-5 * R[i]);
    tcb_sequence_free(&s);
}

/* Subsets of ≥ 3200 points go to tcb_nn's kd-tree (and a serial row loop):
 * the same distances as the naive reference. */
static void test_distances_kdtree_path(void **state)
{
    (void)state;
    enum { F = 2, POOL = 3300 };
    tcb_sequence s;
    make_seq(&s, "big", F, POOL);
    fill_warped(&s, 12);
    double D[F * F], R[F * F];
    tcb_error err = {0};
    assert_int_equal(tcb_cc_frame_distances(&s, POOL, 1, D, &err), TCB_OK);
    ref_matrix(&s, POOL, 1, R);
    for (int i = 0; i < F * F; i++) assert_near(D[i], R[i], 1e-5 * R[i]);
    tcb_sequence_free(&s);
}

/* Rows: A first at distance 0, then the reference order by (distance,
 * index); knn_dist matches the row. */
static void test_knn_rows_reference_order(void **state)
{
    (void)state;
    enum { F = 9, POOL = 200, M = 150, K = 5 };
    tcb_sequence s;
    make_seq(&s, "warp", F, POOL);
    fill_warped(&s, 5);
    double R[F * F];
    for (int in_box = 0; in_box < 2; in_box++) {
        ref_matrix(&s, M, in_box, R);
        tcb_cc_sampler *smp = make_sampler(&s, TCB_CC_SAMPLE_KNN, K, M, in_box, 1);
        assert_int_equal(smp->k, K);
        assert_int_equal(smp->n_frames, F);
        for (int a = 0; a < F; a++) {
            const int32_t *row = smp->knn + a * K;
            assert_int_equal(row[0], a);
            assert_true(smp->knn_dist[a * K] == 0.0);
            /* reference: the other frames by (R, index), by selection */
            int used[F] = {0};
            used[a] = 1;
            for (int j = 1; j < K; j++) {
                int best = -1;
                for (int f = 0; f < F; f++)
                    if (!used[f] && (best < 0 || R[a * F + f] < R[a * F + best])) best = f;
                used[best] = 1;
                if (row[j] != best)
                    fail_msg("in_box %d, row %d, position %d: frame %d, expected %d", in_box, a, j,
                             row[j], best);
                assert_near(smp->knn_dist[a * K + j], R[a * F + best], 1e-5 * R[a * F + best]);
            }
        }
        tcb_cc_sampler_free(smp);
    }
    tcb_sequence_free(&s);
}

/* k = 20 over 5 frames: k = 5, every row a permutation of 0..4 with A first. */
static void test_knn_k_clipped(void **state)
{
    (void)state;
    enum { F = 5 };
    tcb_sequence s;
    make_seq(&s, "warp", F, 64);
    fill_warped(&s, 2);
    tcb_cc_sampler *smp = make_sampler(&s, TCB_CC_SAMPLE_KNN, 20, 2500, 1, 1);
    assert_int_equal(smp->k, F);
    for (int a = 0; a < F; a++) {
        int seen[F] = {0};
        assert_int_equal(smp->knn[a * F], a);
        for (int j = 0; j < F; j++) {
            assert_in_range(smp->knn[a * F + j], 0, F - 1);
            seen[smp->knn[a * F + j]]++;
        }
        for (int f = 0; f < F; f++) assert_int_equal(seen[f], 1);
    }
    tcb_cc_sampler_free(smp);
    /* the default options give k = 20 on a longer sequence */
    tcb_sequence l;
    make_seq(&l, "long", 24, 16);
    fill_warped(&l, 3);
    tcb_cc_sampler_opts o = tcb_cc_sampler_opts_default();
    assert_int_equal(o.knn_k, 20);
    assert_int_equal(o.knn_points, 2500);
    o.sampling = TCB_CC_SAMPLE_KNN;
    tcb_error err = {0};
    assert_int_equal(tcb_cc_sampler_create(&l, &o, &smp, &err), TCB_OK);
    assert_int_equal(smp->k, 20);
    tcb_cc_sampler_free(smp);
    tcb_sequence_free(&l);
    tcb_sequence_free(&s);
}

/* Identical frames: every distance is exactly 0, so each row is A, then the
 * other frames in increasing index (A first although lower indices tie). */
static void test_knn_ties_lower_index(void **state)
{
    (void)state;
    enum { F = 6, POOL = 50 };
    tcb_sequence s;
    make_seq(&s, "still", F, POOL);
    fill_warped(&s, 9);
    for (int f = 1; f < F; f++) memcpy(pool(&s, f), pool(&s, 0), sizeof(float) * 3 * POOL);
    /* frame 5 moves: it must come last in every other row */
    for (int i = 0; i < 3 * POOL; i++) pool(&s, 5)[i] += 0.5f;
    tcb_cc_sampler *smp = make_sampler(&s, TCB_CC_SAMPLE_KNN, F, POOL, 0, 1);
    for (int a = 0; a < F; a++) {
        const int32_t *row = smp->knn + a * F;
        assert_int_equal(row[0], a);
        int expect = 0;
        for (int j = 1; j < F; j++) {
            if (a == 5) { /* all others tie at the same distance */
                assert_int_equal(row[j], j - 1);
                continue;
            }
            while (expect == a || expect == 5) expect++;
            if (j < F - 1) {
                assert_int_equal(row[j], expect++);
                assert_true(smp->knn_dist[a * F + j] == 0.0);
            } else {
                assert_int_equal(row[j], 5);
            }
        }
    }
    tcb_cc_sampler_free(smp);
    tcb_sequence_free(&s);
}

/* Frames are one small cloud translated along x by t_f = 0.3 f + 0.02 f²
 * (steps larger than the cloud, all |t_a − t_b| distinct): raw distances
 * order the neighbours by |t_a − t_b|. In the CC boxes all copies coincide. */
static void test_knn_translated_copies(void **state)
{
    (void)state;
    enum { F = 8, POOL = 120 };
    tcb_sequence s;
    make_seq(&s, "slide", F, POOL);
    tcb_rng r;
    tcb_rng_seed(&r, 4);
    double t[F];
    for (int f = 0; f < F; f++) t[f] = 0.3 * f + 0.02 * f * f;
    for (int i = 0; i < POOL; i++) {
        float p[3];
        for (int d = 0; d < 3; d++) p[d] = (float)(0.1 * tcb_rng_uniform(&r));
        for (int f = 0; f < F; f++) {
            float *q = pool(&s, f) + 3 * i;
            q[0] = p[0] + (float)t[f], q[1] = p[1], q[2] = p[2];
        }
    }
    tcb_cc_sampler *smp = make_sampler(&s, TCB_CC_SAMPLE_KNN, F, POOL, 0, 1);
    for (int a = 0; a < F; a++) {
        int used[F] = {0};
        used[a] = 1;
        assert_int_equal(smp->knn[a * F], a);
        for (int j = 1; j < F; j++) {
            int best = -1;
            for (int f = 0; f < F; f++)
                if (!used[f] && (best < 0 || fabs(t[f] - t[a]) < fabs(t[best] - t[a]))) best = f;
            used[best] = 1;
            assert_int_equal(smp->knn[a * F + j], best);
            assert_true(smp->knn_dist[a * F + j] > smp->knn_dist[a * F + j - 1]);
        }
    }
    tcb_cc_sampler_free(smp);
    double D[F * F];
    tcb_error err = {0};
    assert_int_equal(tcb_cc_frame_distances(&s, POOL, 1, D, &err), TCB_OK);
    for (int i = 0; i < F * F; i++) assert_true(D[i] < 1e-10);
    tcb_sequence_free(&s);
}

/* ---- the draws ------------------------------------------------------------ */

/* Pearson χ² of counts against equal expectations. */
static double chi2_uniform(const int *count, int cells, int total)
{
    double e = (double)total / cells, c2 = 0.0;
    for (int i = 0; i < cells; i++) c2 += (count[i] - e) * (count[i] - e) / e;
    return c2;
}

/* A, B, C independent uniform over 6 frames: each of the 216 (A, B, C)
 * cells equally likely; χ² over 215 degrees of freedom has mean 215 and
 * 99.999th percentile ≈ 320. A sampler returning B = A, or B = C, or a
 * constant, fails by thousands. */
static void test_random_draws_uniform(void **state)
{
    (void)state;
    enum { F = 6, T = 100000 };
    tcb_sequence s;
    make_seq(&s, "warp", F, 4);
    fill_warped(&s, 1);
    tcb_cc_sampler *smp = make_sampler(&s, TCB_CC_SAMPLE_RANDOM, 20, 2500, 1, 1);
    assert_int_equal(smp->k, 0);
    assert_null(smp->knn);
    tcb_rng r;
    tcb_rng_seed(&r, 123);
    static int count[F * F * F];
    memset(count, 0, sizeof count);
    for (int i = 0; i < T; i++) {
        int t[3] = {-1, -1, -1};
        tcb_cc_sampler_draw(smp, &r, t);
        for (int j = 0; j < 3; j++) assert_in_range(t[j], 0, F - 1);
        count[(t[0] * F + t[1]) * F + t[2]]++;
    }
    for (int c = 0; c < F * F * F; c++)
        if (count[c] == 0) fail_msg("triplet (%d, %d, %d) never drawn", c / 36, c / 6 % 6, c % 6);
    double c2 = chi2_uniform(count, F * F * F, T);
    if (c2 > 320.0) fail_msg("chi^2 = %g over 215 degrees of freedom", c2);
    tcb_cc_sampler_free(smp);
    tcb_sequence_free(&s);
}

/* knn, k = 3 of 8 frames: B and C in A's row; (A, B) and (A, C) each uniform
 * over the 24 allowed cells (χ² over 23 dof, 99.999th percentile ≈ 60), and
 * (B, C) given A independent: the 72 (A, B, C) cells, 71 dof, < 130. */
static void test_knn_draws(void **state)
{
    (void)state;
    enum { F = 8, K = 3, T = 60000 };
    tcb_sequence s;
    make_seq(&s, "warp", F, 100);
    fill_warped(&s, 21);
    tcb_cc_sampler *smp = make_sampler(&s, TCB_CC_SAMPLE_KNN, K, 100, 1, 1);
    tcb_rng r;
    tcb_rng_seed(&r, 99);
    int ab[F * K] = {0}, ac[F * K] = {0}, abc[F * K * K] = {0};
    for (int i = 0; i < T; i++) {
        int t[3];
        tcb_cc_sampler_draw(smp, &r, t);
        assert_in_range(t[0], 0, F - 1);
        int pos[3] = {-1, -1, -1};
        for (int j = 1; j < 3; j++) {
            for (int q = 0; q < K; q++)
                if (smp->knn[t[0] * K + q] == t[j]) pos[j] = q;
            if (pos[j] < 0) fail_msg("frame %d is not among the %d neighbours of %d", t[j], K, t[0]);
        }
        ab[t[0] * K + pos[1]]++, ac[t[0] * K + pos[2]]++;
        abc[(t[0] * K + pos[1]) * K + pos[2]]++;
    }
    for (int c = 0; c < F * K; c++) {
        if (ab[c] == 0 || ac[c] == 0) fail_msg("neighbour %d of frame %d never drawn", c % K, c / K);
    }
    double c_ab = chi2_uniform(ab, F * K, T), c_ac = chi2_uniform(ac, F * K, T),
           c_abc = chi2_uniform(abc, F * K * K, T);
    if (c_ab > 60.0 || c_ac > 60.0 || c_abc > 130.0)
        fail_msg("chi^2 (A,B) %g, (A,C) %g over 23 dof; (A,B,C) %g over 71", c_ab, c_ac, c_abc);
    tcb_cc_sampler_free(smp);
    tcb_sequence_free(&s);
}

/* neighbors, delta = 2 over 7 frames: 1 ≤ |B − A| ≤ 2 and likewise C; every
 * allowed (A, B) and (A, C) appears, uniformly given A. Windows clipped at
 * the ends: frame 0 has {1, 2}, frame 3 has {1, 2, 4, 5}. */
static void test_neighbor_draws(void **state)
{
    (void)state;
    enum { F = 7, DELTA = 2, T = 70000 };
    tcb_sequence s;
    make_seq(&s, "warp", F, 4);
    fill_warped(&s, 1);
    tcb_cc_sampler *smp = make_sampler(&s, TCB_CC_SAMPLE_NEIGHBORS, 20, 2500, 1, DELTA);
    tcb_rng r;
    tcb_rng_seed(&r, 5);
    int ab[F][F] = {{0}}, ac[F][F] = {{0}}, na[F] = {0};
    static int abc[F][F][F];
    memset(abc, 0, sizeof abc);
    for (int i = 0; i < T; i++) {
        int t[3];
        tcb_cc_sampler_draw(smp, &r, t);
        for (int j = 0; j < 3; j++) assert_in_range(t[j], 0, F - 1);
        for (int j = 1; j < 3; j++) {
            int d = abs(t[j] - t[0]);
            if (d < 1 || d > DELTA) fail_msg("A = %d, %c = %d", t[0], "ABC"[j], t[j]);
        }
        na[t[0]]++, ab[t[0]][t[1]]++, ac[t[0]][t[2]]++, abc[t[0]][t[1]][t[2]]++;
    }
    double c2 = 0.0;
    int cells = 0;
    for (int a = 0; a < F; a++) {
        int lo = a - DELTA < 0 ? 0 : a - DELTA, hi = a + DELTA >= F ? F - 1 : a + DELTA;
        double e = (double)na[a] / (hi - lo);
        for (int b = lo; b <= hi; b++) {
            if (b == a) continue;
            if (ab[a][b] == 0 || ac[a][b] == 0) fail_msg("(%d, %d) never drawn", a, b);
            c2 += (ab[a][b] - e) * (ab[a][b] - e) / e + (ac[a][b] - e) * (ac[a][b] - e) / e;
            cells += 2;
        }
    }
    assert_int_equal(cells, 2 * 22);
    /* 44 cells, 30 dof after conditioning on A's counts: 99.999th ≈ 75 */
    if (c2 > 75.0) fail_msg("chi^2 = %g", c2);
    /* B and C independent given A: all 74 allowed (A, B, C) appear, uniformly
     * given A (67 dof: 99.999th ≈ 120) */
    c2 = 0.0, cells = 0;
    for (int a = 0; a < F; a++) {
        int lo = a - DELTA < 0 ? 0 : a - DELTA, hi = a + DELTA >= F ? F - 1 : a + DELTA;
        double e = (double)na[a] / ((hi - lo) * (hi - lo));
        for (int b = lo; b <= hi; b++)
            for (int c = lo; c <= hi; c++) {
                if (b == a || c == a) continue;
                if (abc[a][b][c] == 0) fail_msg("(%d, %d, %d) never drawn", a, b, c);
                c2 += (abc[a][b][c] - e) * (abc[a][b][c] - e) / e;
                cells++;
            }
    }
    assert_int_equal(cells, 74);
    if (c2 > 130.0) fail_msg("chi^2 of (A, B, C) = %g over 67 dof", c2);
    /* A itself uniform */
    double ca = chi2_uniform(na, F, T);
    if (ca > 40.0) fail_msg("chi^2 of A = %g over 6 dof", ca);
    tcb_cc_sampler_free(smp);
    tcb_sequence_free(&s);
}

/* Same seed → the same triplets; another seed → others. The draw order
 * A, B, C is fixed: the first number of the stream picks A. */
static void test_reproducible(void **state)
{
    (void)state;
    enum { F = 10, T = 200 };
    tcb_sequence s;
    make_seq(&s, "warp", F, 40);
    fill_warped(&s, 8);
    for (int mode = 0; mode < 3; mode++) {
        tcb_cc_sampler *smp = make_sampler(&s, (tcb_cc_sampling)mode, 4, 40, 1, 2);
        int x[T][3], y[T][3], z[T][3];
        tcb_rng r1, r2, r3;
        tcb_rng_seed(&r1, 77), tcb_rng_seed(&r2, 77), tcb_rng_seed(&r3, 78);
        for (int i = 0; i < T; i++) {
            tcb_cc_sampler_draw(smp, &r1, x[i]);
            tcb_cc_sampler_draw(smp, &r2, y[i]);
            tcb_cc_sampler_draw(smp, &r3, z[i]);
        }
        assert_memory_equal(x, y, sizeof x);
        assert_memory_not_equal(x, z, sizeof x);
        /* A is the stream's first draw */
        tcb_rng q;
        tcb_rng_seed(&q, 77);
        assert_int_equal(x[0][0], (int)tcb_rng_below(&q, F));
        /* a second sampler built the same way draws the same */
        tcb_cc_sampler *again = make_sampler(&s, (tcb_cc_sampling)mode, 4, 40, 1, 2);
        tcb_rng_seed(&r1, 77);
        for (int i = 0; i < T; i++) {
            int t[3];
            tcb_cc_sampler_draw(again, &r1, t);
            assert_memory_equal(t, x[i], sizeof t);
        }
        tcb_cc_sampler_free(again);
        tcb_cc_sampler_free(smp);
    }
    tcb_sequence_free(&s);
}

/* ---- errors ----------------------------------------------------------------- */

static void expect_error(int rc, const tcb_error *err, int code, const char *a, const char *b)
{
    assert_int_equal(rc, code);
    if (a && !strstr(err->msg, a)) fail_msg("'%s' does not name '%s'", err->msg, a);
    if (b && !strstr(err->msg, b)) fail_msg("'%s' does not name '%s'", err->msg, b);
}

static void test_rejects(void **state)
{
    (void)state;
    tcb_cc_sampler_opts o = tcb_cc_sampler_opts_default();
    tcb_cc_sampler dummy, *smp = &dummy; /* create must reset it to NULL */
    tcb_error err = {0};

    tcb_sequence one;
    make_seq(&one, "lonely_frame", 1, 8);
    fill_warped(&one, 1);
    for (int mode = 0; mode < 3; mode++) {
        o.sampling = (tcb_cc_sampling)mode;
        expect_error(tcb_cc_sampler_create(&one, &o, &smp, &err), &err, TCB_ERR_INPUT,
                     "lonely_frame", NULL);
        assert_null(smp);
    }
    tcb_sequence_free(&one);

    tcb_sequence s;
    make_seq(&s, "cat_walk", 4, 16);
    fill_warped(&s, 1);
    o = tcb_cc_sampler_opts_default();
    o.sampling = TCB_CC_SAMPLE_NEIGHBORS, o.delta = 0;
    expect_error(tcb_cc_sampler_create(&s, &o, &smp, &err), &err, TCB_ERR_INPUT, "cat_walk", "delta");
    o = tcb_cc_sampler_opts_default();
    o.sampling = TCB_CC_SAMPLE_KNN, o.knn_k = 0;
    expect_error(tcb_cc_sampler_create(&s, &o, &smp, &err), &err, TCB_ERR_INPUT, "cat_walk", NULL);
    o.knn_k = 3, o.knn_points = 0;
    expect_error(tcb_cc_sampler_create(&s, &o, &smp, &err), &err, TCB_ERR_INPUT, "cat_walk", NULL);
    o = tcb_cc_sampler_opts_default();
    o.sampling = (tcb_cc_sampling)7;
    expect_error(tcb_cc_sampler_create(&s, &o, &smp, &err), &err, TCB_ERR_INPUT, "cat_walk", NULL);

    /* a degenerate frame (all pool points equal) has no CC box */
    o = tcb_cc_sampler_opts_default();
    o.sampling = TCB_CC_SAMPLE_KNN;
    for (int i = 0; i < s.pool_size; i++) memcpy(pool(&s, 2) + 3 * i, pool(&s, 2), 3 * sizeof(float));
    expect_error(tcb_cc_sampler_create(&s, &o, &smp, &err), &err, TCB_ERR_INPUT, "cat_walk", "frame 2");
    assert_null(smp);
    /* ... but raw distances do not need one */
    o.knn_in_box = 0;
    assert_int_equal(tcb_cc_sampler_create(&s, &o, &smp, &err), TCB_OK);
    tcb_cc_sampler_free(smp);
    /* non-finite pool points */
    pool(&s, 3)[4] = NAN;
    int rc = tcb_cc_sampler_create(&s, &o, &smp, &err);
    if (rc != TCB_ERR_NUMERIC && rc != TCB_ERR_INPUT) fail_msg("rc = %d: %s", rc, err.msg);
    if (!strstr(err.msg, "cat_walk")) fail_msg("'%s' does not name the sequence", err.msg);
    assert_null(smp);

    /* knn without pools; random and neighbors do not need them */
    free(s.pools);
    s.pools = NULL, s.pool_size = 0;
    expect_error(tcb_cc_sampler_create(&s, &o, &smp, &err), &err, TCB_ERR_INPUT, "cat_walk", "pool");
    o.sampling = TCB_CC_SAMPLE_RANDOM;
    assert_int_equal(tcb_cc_sampler_create(&s, &o, &smp, &err), TCB_OK);
    tcb_cc_sampler_free(smp);
    tcb_cc_sampler_free(NULL);
    tcb_sequence_free(&s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_parse),
        cmocka_unit_test(test_distances_match_reference),
        cmocka_unit_test(test_distances_kdtree_path),
        cmocka_unit_test(test_knn_rows_reference_order),
        cmocka_unit_test(test_knn_k_clipped),
        cmocka_unit_test(test_knn_ties_lower_index),
        cmocka_unit_test(test_knn_translated_copies),
        cmocka_unit_test(test_random_draws_uniform),
        cmocka_unit_test(test_knn_draws),
        cmocka_unit_test(test_neighbor_draws),
        cmocka_unit_test(test_reproducible),
        cmocka_unit_test(test_rejects),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
