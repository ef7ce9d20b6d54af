/* Evaluation metrics: hand-computed cases, and an independent naive
 * implementation written from reference-protocol §5.4–§5.5 (no code shared
 * with metrics/) compared on random inputs. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "tcb/metrics.h"
#include "tcb/rng.h"

#define REL 1e-12

static void check_close(double got, double want, double rel, const char *what)
{
    if (!(fabs(got - want) <= rel * fmax(fabs(got), fabs(want))))
        fail_msg("%s: got %.17g, want %.17g", what, got, want);
}

/* ---- the independent reference -------------------------------------------- */

/* |a − b|², summed over the three axes in double. */
static double sqdist(const float *a, const float *b)
{
    double s = 0.0;
    for (int c = 0; c < 3; c++) s += ((double)a[c] - b[c]) * ((double)a[c] - b[c]);
    return s;
}

/* numpy.linspace(0, 0.02, 100): i·(0.02/99), the last one exactly 0.02. */
static double np_linspace_002(int s) { return s == 99 ? 0.02 : s * (0.02 / 99); }

typedef struct {
    int k;
    double *sl2, *sl2sq, *rank; /* per vertex [k] */
    double pck[100];
    double auc;
} ref_pair;

static void ref_compute(const float *v, int K, const int32_t *pred, ref_pair *r)
{
    r->k = K;
    r->sl2 = malloc(K * sizeof(double)), r->sl2sq = malloc(K * sizeof(double));
    r->rank = malloc(K * sizeof(double));
    for (int k = 0; k < K; k++) {
        double d = sqdist(v + 3 * pred[k], v + 3 * k);
        r->sl2sq[k] = d;
        r->sl2[k] = sqrt(d);
        int closer = 0;
        for (int l = 0; l < K; l++)
            if (sqdist(v + 3 * l, v + 3 * k) < d) closer++;
        r->rank[k] = (double)closer / K;
    }
    r->auc = 0.0;
    for (int s = 0; s < 100; s++) {
        int within = 0;
        for (int k = 0; k < K; k++)
            if (r->sl2sq[k] <= np_linspace_002(s)) within++;
        r->pck[s] = (double)within / K;
        r->auc += r->pck[s];
    }
    r->auc /= 100;
}

static void ref_free(ref_pair *r) { free(r->sl2), free(r->sl2sq), free(r->rank); }

/* Two-pass mean and population std (numpy, ddof = 0). */
static void naive_stats(const double *x, int n, double *mean, double *std)
{
    double s = 0.0, q = 0.0;
    for (int i = 0; i < n; i++) s += x[i];
    *mean = s / n;
    for (int i = 0; i < n; i++) q += (x[i] - *mean) * (x[i] - *mean);
    *std = sqrt(q / n);
}

static void check_stat(const tcb_stat *st, const double *x, int n, const char *what)
{
    double mean, std;
    naive_stats(x, n, &mean, &std);
    assert_true(st->n == n);
    check_close(st->mean, mean, REL, what);
    check_close(tcb_stat_std(st), std, REL, what);
}

/* ---- random inputs --------------------------------------------------------- */

static float *random_verts(int K, tcb_rng *rng)
{
    float *v = malloc((size_t)K * 3 * sizeof(float));
    for (int i = 0; i < 3 * K; i++) v[i] = (float)tcb_rng_uniform(rng);
    return v;
}

/* A plausible method: a third exact, a third a near vertex id, a third anywhere. */
static int32_t *random_pred(int K, tcb_rng *rng)
{
    int32_t *p = malloc((size_t)K * sizeof(int32_t));
    for (int k = 0; k < K; k++) {
        int kind = (int)tcb_rng_below(rng, 3);
        int near = k - 5 + (int)tcb_rng_below(rng, 11);
        p[k] = kind == 0 ? k : kind == 1 ? (near < 0 ? 0 : near >= K ? K - 1 : near)
                                         : (int32_t)tcb_rng_below(rng, (uint32_t)K);
    }
    return p;
}

static void check_pair(const tcb_pair_metrics *m, const ref_pair *r)
{
    check_stat(&m->sl2, r->sl2, r->k, "sl2");
    check_stat(&m->sl2sq, r->sl2sq, r->k, "sl2sq");
    check_stat(&m->rank, r->rank, r->k, "rank");
    for (int s = 0; s < 100; s++) check_close(m->pck[s], r->pck[s], REL, "pck");
    check_close(m->auc, r->auc, REL, "auc");
}

/* ---- stat ------------------------------------------------------------------ */

static void test_stat_push_merge(void **state)
{
    (void)state;
    tcb_stat a = {0}, b = {0}, all = {0}, empty = {0};
    assert_true(isnan(tcb_stat_std(&empty)));
    const double x[] = {1, 2, 3, 4, 10.5, -3};
    for (int i = 0; i < 6; i++) {
        tcb_stat_push(i < 2 ? &a : &b, x[i]);
        tcb_stat_push(&all, x[i]);
    }
    tcb_stat_push(&empty, 7.0);
    assert_true(empty.mean == 7.0 && tcb_stat_std(&empty) == 0.0);
    tcb_stat m = a;
    tcb_stat_merge(&m, &b);
    check_stat(&m, x, 6, "merged");
    check_stat(&all, x, 6, "pushed");
    tcb_stat z = {0};
    tcb_stat_merge(&z, &all); /* into empty: a copy */
    assert_memory_equal(&z, &all, sizeof z);
    tcb_stat_merge(&all, &(tcb_stat){0}); /* empty other: no change */
    assert_memory_equal(&z, &all, sizeof z);
}

/* ---- hand-computed cases ----------------------------------------------------- */

/* Four vertices on the x axis at 0, 1/16, 1/8, 1/4 (exact in binary);
 * pred = [1, 1, 0, 2]:
 *   k  d_k      sqrt   closer than d_k (strict)                    rank
 *   0  1/256    1/16   {0}                                          1/4
 *   1  0        0      (exact)                                      0
 *   2  1/64     1/8    {1, 2}; 0 and 3 are at exactly d_k: excluded 2/4
 *   3  1/64     1/8    {3}; 2 is at exactly d_k: excluded            1/4
 * PCK: d ≤ s·0.02/99 holds for 0 at s ≥ 0, 1/256 at s ≥ 20, 1/64 at s ≥ 78,
 * so PCK = 1/4 (s < 20), 1/2 (s < 78), 1 (s ≥ 78);
 * AUC = (20·0.25 + 58·0.5 + 22·1)/100 = 0.56. */
static void test_line_by_hand(void **state)
{
    (void)state;
    const float v[] = {0, 0, 0, 0.0625f, 0, 0, 0.125f, 0, 0, 0.25f, 0, 0};
    const int32_t pred[] = {1, 1, 0, 2};
    tcb_pair_metrics m;
    tcb_error err = {0};
    assert_int_equal(tcb_pair_metrics_compute(v, 4, pred, &m, &err), TCB_OK);
    assert_true(m.sl2.n == 4);
    check_close(m.sl2.mean, (0.0625 + 0.125 + 0.125) / 4, 1e-15, "sl2");
    check_close(m.sl2sq.mean, (1.0 / 256 + 2.0 / 64) / 4, 1e-15, "sl2sq");
    check_close(m.rank.mean, 0.25, 1e-15, "rank");
    const double sl2[] = {0.0625, 0, 0.125, 0.125}, rank[] = {0.25, 0, 0.5, 0.25};
    check_stat(&m.sl2, sl2, 4, "sl2");
    check_stat(&m.rank, rank, 4, "rank");
    for (int s = 0; s < 100; s++) {
        double want = s < 20 ? 0.25 : s < 78 ? 0.5 : 1.0;
        if (m.pck[s] != want) fail_msg("pck[%d] = %g, want %g", s, m.pck[s], want);
    }
    check_close(m.auc, 0.56, 1e-15, "auc");
}

/* Equidistant vertices are not closer: v1, v2, v3 at distance 1 from v0,
 * pred[0] = 1, so only v0 itself (distance 0) is strictly closer. */
static void test_rank_strict(void **state)
{
    (void)state;
    const float v[] = {0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, 0};
    const int32_t pred[] = {1, 1, 2, 3};
    tcb_pair_metrics m;
    assert_int_equal(tcb_pair_metrics_compute(v, 4, pred, &m, NULL), TCB_OK);
    check_close(m.rank.mean, 0.25 / 4, 1e-15, "rank");
    check_close(m.sl2.mean, 0.25, 1e-15, "sl2");
    assert_true(m.pck[0] == 0.75 && m.pck[99] == 0.75);
}

static void test_identity(void **state)
{
    (void)state;
    tcb_rng rng;
    tcb_rng_seed(&rng, 3);
    float *v = random_verts(500, &rng);
    int32_t pred[500];
    for (int k = 0; k < 500; k++) pred[k] = k;
    tcb_pair_metrics m;
    assert_int_equal(tcb_pair_metrics_compute(v, 500, pred, &m, NULL), TCB_OK);
    assert_true(m.sl2.mean == 0.0 && m.sl2sq.mean == 0.0 && m.rank.mean == 0.0);
    assert_true(tcb_stat_std(&m.sl2) == 0.0 && tcb_stat_std(&m.rank) == 0.0);
    for (int s = 0; s < TCB_PCK_STEPS; s++) assert_true(m.pck[s] == 1.0);
    assert_true(m.auc == 1.0);
    free(v);
}

/* Thresholds include both ends: 0 counts exact matches, 0.02 counts a
 * squared error of exactly 0.02. The offsets below were searched so that
 * (dx² + dy²) + dz² rounds to the double 0.02 exactly; bumping dy by one
 * float ulp lands above it. */
static void test_pck_inclusive_ends(void **state)
{
    (void)state;
    const float dx = 0x1.b19f04p-4f, dy = 0x1.801456p-4f, dz = 0x1.a27444p-26f;
    const float dy_up = 0x1.801458p-4f;
    const float v[] = {0, 0, 0, dx, dy, dz, dx, dy_up, dz};
    assert_true(tcb_pck_threshold(0) == 0.0);
    assert_true(tcb_pck_threshold(TCB_PCK_STEPS - 1) == 0.02);
    assert_true(sqdist(v + 3, v) == 0.02 && sqdist(v + 6, v) > 0.02); /* the fixture */

    tcb_pair_metrics m;
    const int32_t at[] = {1, 1, 2}, above[] = {2, 1, 2};
    assert_int_equal(tcb_pair_metrics_compute(v, 3, at, &m, NULL), TCB_OK);
    assert_true(m.pck[0] == 2.0 / 3 && m.pck[98] == 2.0 / 3 && m.pck[99] == 1.0);
    assert_int_equal(tcb_pair_metrics_compute(v, 3, above, &m, NULL), TCB_OK);
    assert_true(m.pck[99] == 2.0 / 3);
}

static void test_thresholds_linspace(void **state)
{
    (void)state;
    for (int s = 0; s < TCB_PCK_STEPS; s++) assert_true(tcb_pck_threshold(s) == np_linspace_002(s));
    for (int s = 1; s < TCB_PCK_STEPS; s++) assert_true(tcb_pck_threshold(s) > tcb_pck_threshold(s - 1));
}

/* ---- random inputs vs the reference ------------------------------------------- */

static void test_pair_vs_reference(void **state)
{
    (void)state;
    static const int sizes[] = {1, 2, 17, 300, 1297};
    for (uint64_t seed = 1; seed <= 3; seed++) {
        for (size_t s = 0; s < sizeof sizes / sizeof *sizes; s++) {
            int K = sizes[s];
            tcb_rng rng;
            tcb_rng_seed(&rng, seed * 100 + s);
            float *v = random_verts(K, &rng);
            int32_t *pred = random_pred(K, &rng);
            tcb_pair_metrics m;
            tcb_error err = {0};
            assert_int_equal(tcb_pair_metrics_compute(v, K, pred, &m, &err), TCB_OK);
            ref_pair r;
            ref_compute(v, K, pred, &r);
            check_pair(&m, &r);
            ref_free(&r);
            free(v), free(pred);
        }
    }
}

/* The per-vertex values equal the reference's bit for bit (the same
 * expressions; a rank is an exact count over K), their summary is the
 * pair's metrics bit for bit, and rank may be left out. On the lattice
 * too, where ties decide the ranks. */
static void check_vertex_metrics(const float *v, int K, const int32_t *pred)
{
    double *sq = malloc((size_t)K * sizeof *sq), *rank = malloc((size_t)K * sizeof *rank);
    double *sq_only = malloc((size_t)K * sizeof *sq_only);
    assert_int_equal(tcb_pair_vertex_metrics(v, K, pred, sq, rank, NULL), TCB_OK);
    assert_int_equal(tcb_pair_vertex_metrics(v, K, pred, sq_only, NULL, NULL), TCB_OK);
    ref_pair r;
    ref_compute(v, K, pred, &r);
    for (int k = 0; k < K; k++) {
        assert_true(sq[k] == r.sl2sq[k] && sq_only[k] == sq[k]);
        assert_true(rank[k] == r.rank[k]);
    }
    tcb_pair_metrics whole, parts;
    assert_int_equal(tcb_pair_metrics_compute(v, K, pred, &whole, NULL), TCB_OK);
    tcb_pair_metrics_summarize(sq, rank, K, &parts);
    assert_memory_equal(&whole, &parts, sizeof whole);
    ref_free(&r);
    free(sq), free(rank), free(sq_only);
}

static void test_vertex_metrics(void **state)
{
    (void)state;
    tcb_rng rng;
    tcb_rng_seed(&rng, 11);
    float *v = random_verts(1297, &rng);
    int32_t *pred = random_pred(1297, &rng);
    check_vertex_metrics(v, 1297, pred);
    free(v), free(pred);
    enum { K = 343 };
    float lattice[3 * K];
    for (int k = 0; k < K; k++) lattice[3 * k] = k % 7, lattice[3 * k + 1] = k / 7 % 7, lattice[3 * k + 2] = k / 49;
    pred = random_pred(K, &rng);
    check_vertex_metrics(lattice, K, pred);
    free(pred);
}

/* Integer coordinates: many exactly equal distances, where < vs ≤ matters. */
static void test_pair_vs_reference_lattice(void **state)
{
    (void)state;
    enum { K = 343 };
    float v[3 * K];
    for (int k = 0; k < K; k++) v[3 * k] = k % 7, v[3 * k + 1] = k / 7 % 7, v[3 * k + 2] = k / 49;
    tcb_rng rng;
    tcb_rng_seed(&rng, 9);
    int32_t *pred = random_pred(K, &rng);
    tcb_pair_metrics m;
    assert_int_equal(tcb_pair_metrics_compute(v, K, pred, &m, NULL), TCB_OK);
    ref_pair r;
    ref_compute(v, K, pred, &r);
    check_pair(&m, &r);
    ref_free(&r);
    free(pred);
}

static void test_project_to_vertices(void **state)
{
    (void)state;
    tcb_rng rng;
    tcb_rng_seed(&rng, 4);
    float *v = random_verts(1297, &rng), *pts = random_verts(400, &rng);
    int32_t idx[400];
    assert_int_equal(tcb_project_to_vertices(v, 1297, pts, 400, idx, NULL), TCB_OK);
    for (int q = 0; q < 400; q++) {
        int best = 0;
        for (int l = 1; l < 1297; l++)
            if (sqdist(v + 3 * l, pts + 3 * q) < sqdist(v + 3 * best, pts + 3 * q)) best = l;
        assert_int_equal(idx[q], best);
    }
    free(v), free(pts);
}

/* ---- Chamfer and the atlas transfer ---------------------------------------------- */

static double naive_chamfer_dir(const float *a, int na, const float *b, int nb)
{
    double sum = 0.0;
    for (int i = 0; i < na; i++) {
        double best = INFINITY;
        for (int j = 0; j < nb; j++) best = fmin(best, sqdist(a + 3 * i, b + 3 * j));
        sum += best;
    }
    return sum / na;
}

static void test_chamfer(void **state)
{
    (void)state;
    /* by hand: a→b = 1; b→a = (1 + 4)/2 */
    const float a[] = {0, 0, 0}, b[] = {1, 0, 0, 0, 2, 0};
    double cd;
    assert_int_equal(tcb_chamfer(a, 1, b, 2, &cd, NULL), TCB_OK);
    assert_true(cd == 3.5);
    assert_int_equal(tcb_chamfer(b, 2, b, 2, &cd, NULL), TCB_OK);
    assert_true(cd == 0.0);

    static const int sizes[][2] = {{1, 1}, {200, 1297}, {3125, 1297}, {5000, 4000}};
    for (size_t s = 0; s < sizeof sizes / sizeof *sizes; s++) {
        tcb_rng rng;
        tcb_rng_seed(&rng, 50 + s);
        int na = sizes[s][0], nb = sizes[s][1];
        float *pa = random_verts(na, &rng), *pb = random_verts(nb, &rng);
        assert_int_equal(tcb_chamfer(pa, na, pb, nb, &cd, NULL), TCB_OK);
        double want = naive_chamfer_dir(pa, na, pb, nb) + naive_chamfer_dir(pb, nb, pa, na);
        /* The neighbour is chosen in float, so a float near-tie may pick a
         * point whose double distance is one float rounding off the minimum. */
        check_close(cd, want, 1e-9, "chamfer");
        free(pa), free(pb);
    }
}

static void test_atlas_transfer(void **state)
{
    (void)state;
    /* by hand: (0,0,0) is equidistant from pred_i[0] and pred_i[2] → lowest id */
    const float src[] = {0, 0, 0, 10, 0, 0};
    const float pi[] = {1, 0, 0, 9, 0, 0, 0, 1, 0}, pj[] = {5, 5, 5, 6, 6, 6, 7, 7, 7};
    float out[6];
    assert_int_equal(tcb_atlas_transfer(src, 2, pi, pj, 3, out, NULL), TCB_OK);
    const float want[] = {5, 5, 5, 6, 6, 6};
    assert_memory_equal(out, want, sizeof want);

    static const int ms[] = {3120, 6000};
    for (size_t s = 0; s < 2; s++) {
        int m = ms[s], n = 1297;
        tcb_rng rng;
        tcb_rng_seed(&rng, 70 + s);
        float *q = random_verts(n, &rng), *a = random_verts(m, &rng), *b = random_verts(m, &rng);
        float *o = malloc((size_t)n * 3 * sizeof(float));
        assert_int_equal(tcb_atlas_transfer(q, n, a, b, m, o, NULL), TCB_OK);
        for (int k = 0; k < n; k++) {
            int best = 0;
            for (int l = 1; l < m; l++)
                if (sqdist(a + 3 * l, q + 3 * k) < sqdist(a + 3 * best, q + 3 * k)) best = l;
            assert_memory_equal(o + 3 * k, b + 3 * best, 3 * sizeof(float));
        }
        free(q), free(a), free(b), free(o);
    }
}

/* ---- summaries ------------------------------------------------------------------ */

enum { NP = 7 };
static const int pair_k[NP] = {50, 120, 1, 300, 77, 120, 9};
static const double pair_cd[NP] = {0.5, NAN, 0.25, 1.5, NAN, 0.125, 3.0};

static void make_pairs(tcb_pair_metrics *m, ref_pair *r)
{
    for (int p = 0; p < NP; p++) {
        tcb_rng rng;
        tcb_rng_seed(&rng, 1000 + p);
        float *v = random_verts(pair_k[p], &rng);
        int32_t *pred = random_pred(pair_k[p], &rng);
        assert_int_equal(tcb_pair_metrics_compute(v, pair_k[p], pred, &m[p], NULL), TCB_OK);
        ref_compute(v, pair_k[p], pred, &r[p]);
        free(v), free(pred);
    }
}

static tcb_summary summary_of(const tcb_pair_metrics *m, int from, int to)
{
    tcb_summary s;
    tcb_summary_init(&s);
    for (int p = from; p < to; p++) tcb_summary_add_pair(&s, &m[p], pair_cd[p]);
    return s;
}

static void check_summary_close(const tcb_summary *a, const tcb_summary *b)
{
    assert_int_equal(a->n_pairs, b->n_pairs);
    const tcb_stat *sa[] = {&a->sl2, &a->sl2sq, &a->rank, &a->auc, &a->cd};
    const tcb_stat *sb[] = {&b->sl2, &b->sl2sq, &b->rank, &b->auc, &b->cd};
    for (int i = 0; i < 5; i++) {
        assert_true(sa[i]->n == sb[i]->n);
        check_close(sa[i]->mean, sb[i]->mean, REL, "mean");
        check_close(tcb_stat_std(sa[i]), tcb_stat_std(sb[i]), REL, "std");
    }
    for (int s = 0; s < TCB_PCK_STEPS; s++) check_close(a->pck[s], b->pck[s], REL, "pck");
}

static void test_summary_pools_vertices(void **state)
{
    (void)state;
    tcb_pair_metrics m[NP];
    ref_pair r[NP];
    make_pairs(m, r);
    tcb_summary s = summary_of(m, 0, NP);
    assert_int_equal(s.n_pairs, NP);

    int total = 0;
    for (int p = 0; p < NP; p++) total += pair_k[p];
    double *sl2 = malloc(total * sizeof(double)), *sl2sq = malloc(total * sizeof(double));
    double *rank = malloc(total * sizeof(double));
    double auc[NP], cd[NP];
    int off = 0, ncd = 0;
    for (int p = 0; p < NP; p++) {
        memcpy(sl2 + off, r[p].sl2, pair_k[p] * sizeof(double));
        memcpy(sl2sq + off, r[p].sl2sq, pair_k[p] * sizeof(double));
        memcpy(rank + off, r[p].rank, pair_k[p] * sizeof(double));
        off += pair_k[p];
        auc[p] = r[p].auc;
        if (!isnan(pair_cd[p])) cd[ncd++] = pair_cd[p];
    }
    check_stat(&s.sl2, sl2, total, "pooled sl2");
    check_stat(&s.sl2sq, sl2sq, total, "pooled sl2sq");
    check_stat(&s.rank, rank, total, "pooled rank");
    check_stat(&s.auc, auc, NP, "auc over pairs");
    check_stat(&s.cd, cd, ncd, "cd over pairs");
    for (int st = 0; st < TCB_PCK_STEPS; st++) {
        double mean = 0.0;
        for (int p = 0; p < NP; p++) mean += r[p].pck[st];
        check_close(s.pck[st], mean / NP, REL, "pck curve");
    }
    free(sl2), free(sl2sq), free(rank);
    for (int p = 0; p < NP; p++) ref_free(&r[p]);
}

static void test_summary_merge(void **state)
{
    (void)state;
    tcb_pair_metrics m[NP];
    ref_pair r[NP];
    make_pairs(m, r);
    tcb_summary all = summary_of(m, 0, NP);
    tcb_summary a = summary_of(m, 0, 3), b = summary_of(m, 3, 5), c = summary_of(m, 5, NP);

    tcb_summary left = a, right = b;
    tcb_summary_merge(&left, &b);
    tcb_summary_merge(&left, &c); /* (a ∪ b) ∪ c */
    tcb_summary_merge(&right, &c);
    tcb_summary a2 = a;
    tcb_summary_merge(&a2, &right); /* a ∪ (b ∪ c) */
    check_summary_close(&left, &all);
    check_summary_close(&a2, &all);

    tcb_summary empty, e2;
    tcb_summary_init(&empty);
    e2 = empty;
    tcb_summary_merge(&e2, &all);
    assert_memory_equal(&e2, &all, sizeof all);
    tcb_summary_merge(&e2, &empty);
    assert_memory_equal(&e2, &all, sizeof all);
    for (int p = 0; p < NP; p++) ref_free(&r[p]);
}

static void test_summary_without_cd(void **state)
{
    (void)state;
    tcb_pair_metrics m[NP];
    ref_pair r[NP];
    make_pairs(m, r);
    tcb_summary s;
    tcb_summary_init(&s);
    for (int p = 0; p < NP; p++) tcb_summary_add_pair(&s, &m[p], NAN);
    assert_true(s.cd.n == 0 && isnan(tcb_stat_std(&s.cd)));
    assert_true(s.auc.n == NP);
    for (int p = 0; p < NP; p++) ref_free(&r[p]);
}

static void test_errors(void **state)
{
    (void)state;
    const float v[] = {0, 0, 0, 1, 0, 0};
    const int32_t bad[] = {0, 2};
    tcb_pair_metrics m;
    tcb_error err = {0};
    assert_int_equal(tcb_pair_metrics_compute(v, 2, bad, &m, &err), TCB_ERR_INPUT);
    assert_non_null(strstr(err.msg, "pred[1]"));
    assert_int_equal(tcb_pair_metrics_compute(v, 0, bad, &m, &err), TCB_ERR_INPUT);
    double sq[2];
    assert_int_equal(tcb_pair_vertex_metrics(v, 2, bad, sq, NULL, &err), TCB_ERR_INPUT);
    assert_non_null(strstr(err.msg, "pred[1] = 2 outside [0, 2)"));
    double cd;
    assert_int_equal(tcb_chamfer(v, 0, v, 2, &cd, &err), TCB_ERR_INPUT);
    float out[3];
    assert_int_equal(tcb_atlas_transfer(v, 1, v, v, 0, out, &err), TCB_ERR_INPUT);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_stat_push_merge),
        cmocka_unit_test(test_line_by_hand),
        cmocka_unit_test(test_rank_strict),
        cmocka_unit_test(test_identity),
        cmocka_unit_test(test_pck_inclusive_ends),
        cmocka_unit_test(test_thresholds_linspace),
        cmocka_unit_test(test_pair_vs_reference),
        cmocka_unit_test(test_pair_vs_reference_lattice),
        cmocka_unit_test(test_vertex_metrics),
        cmocka_unit_test(test_project_to_vertices),
        cmocka_unit_test(test_chamfer),
        cmocka_unit_test(test_atlas_transfer),
        cmocka_unit_test(test_summary_pools_vertices),
        cmocka_unit_test(test_summary_merge),
        cmocka_unit_test(test_summary_without_cd),
        cmocka_unit_test(test_errors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
