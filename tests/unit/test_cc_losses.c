/* CC losses (methods/cycle/losses.h): values against a brute-force
 * double-precision reference transcribed here from the CC code by its own
 * tensor names (compute_loss_cycle2/3, batch_cycle_2/3, chamferL2_assym2),
 * gradients of every entry against central finite differences of that
 * reference with the nearest-neighbour indices frozen (the detached-index
 * gradient), checking that the perturbations do not move any index, so the
 * frozen objective is the true one locally. Plus the gradient's support
 * (only gathered points are pulled), thread-count independence, errors,
 * and tcb_cc_rms.
 *
 * Values: 1e-10 relative (both sides are double from the same floats).
 * Gradients, per entry: |analytic − FD| ≤ 1e-5·|FD| + 1e-6·max|FD|. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "methods/cycle/losses.h"
#include "tcb/rng.h"
#include "testutil.h"

#define NB 2
#define NP 40
#define NPAIR 6
#define SZ_P (3 * NB * NP * 3)
#define SZ_D (NPAIR * NB * NP * 3)
#define FD_REL 1e-6
#define EPS 1e-8

/* ---- the reference, in CC's names --------------------------------------- */

/* CC's deformations in the order its trainer computes them; X_Y is Y
 * deformed towards X (shapes 1-based, as in CC). */
enum { P2_P1, P1_P2, P3_P2, P2_P3, P1_P3, P3_P1 };
static const int cc_src[NPAIR] = {1, 2, 2, 3, 3, 1}; /* Y of X_Y */
static const int cc_tgt[NPAIR] = {2, 1, 3, 2, 1, 3}; /* X of X_Y */

/* compute_loss_cycle2: L2(batch_cycle_2(gathered, idx1_<idx>), P<shape>). */
static const int cc_cycle2[NPAIR][3] = {
    {P1_P2, P2_P1, 1}, {P2_P1, P1_P2, 2}, {P3_P2, P2_P3, 3},
    {P2_P3, P3_P2, 2}, {P1_P3, P3_P1, 1}, {P3_P1, P1_P3, 3},
};

/* compute_loss_cycle3: L2(batch_cycle_3(T, idx1_<a>, idx1_<b>), P<shape>),
 * and batch_cycle_3(T, a, b)[m] = T.view(-1, 3)[b][a][m] = T[b[a[m]]]. */
static const int cc_cycle3[NPAIR][4] = {
    {P1_P3, P2_P1, P3_P2, 1}, {P2_P1, P3_P2, P1_P3, 2}, {P3_P2, P1_P3, P2_P1, 3},
    {P1_P2, P3_P1, P2_P3, 1}, {P2_P3, P1_P2, P3_P1, 2}, {P3_P1, P2_P3, P1_P2, 3},
};

/* distChamfer(X_Y, P_X): idx1 = for each deformed point its NN in P_X,
 * idx2 = for each point of P_X its NN among the deformed points. */
typedef struct {
    int32_t idx1[NPAIR][NB][NP], idx2[NPAIR][NB][NP];
} maps;

typedef struct {
    double P[SZ_P], D[SZ_D];
    maps frozen;
} ref_case;

typedef struct {
    double chamfer, cycle2, cycle3;
    double rms2[NPAIR], rms3[NPAIR]; /* each L2(...) of cycle2 resp. cycle3 */
} ref_terms;

static const double *shape(const ref_case *r, int one_based, int b)
{
    return r->P + ((size_t)(one_based - 1) * NB + b) * NP * 3;
}

static const double *def(const ref_case *r, int k, int b)
{
    return r->D + ((size_t)k * NB + b) * NP * 3;
}

static double d2(const double *a, const double *b)
{
    return (a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
           (a[2] - b[2]) * (a[2] - b[2]);
}

static int32_t argmin(const double *q, const double *set)
{
    int32_t best = 0;
    for (int j = 1; j < NP; j++)
        if (d2(q, set + 3 * j) < d2(q, set + 3 * best)) best = j;
    return best;
}

/* The maps of deformation k in shape b, the only ones D_k[b] moves. */
static void ref_maps_of(const ref_case *r, int k, int b, int32_t *idx1, int32_t *idx2)
{
    const double *x = def(r, k, b), *t = shape(r, cc_tgt[k], b);
    for (int m = 0; m < NP; m++) idx1[m] = argmin(x + 3 * m, t);
    for (int q = 0; q < NP; q++) idx2[q] = argmin(t + 3 * q, x);
}

static void ref_maps(const ref_case *r, maps *out)
{
    for (int k = 0; k < NPAIR; k++)
        for (int b = 0; b < NB; b++) ref_maps_of(r, k, b, out->idx1[k][b], out->idx2[k][b]);
}

/* The CC losses at r->D with r->frozen's indices. */
static void ref_eval(const ref_case *r, ref_terms *t)
{
    const maps *f = &r->frozen;
    double n = NB * NP, ch = 0.0;
    for (int k = 0; k < NPAIR; k++)
        for (int b = 0; b < NB; b++)
            for (int q = 0; q < NP; q++)
                ch += sqrt(d2(def(r, k, b) + 3 * f->idx2[k][b][q], shape(r, cc_tgt[k], b) + 3 * q));
    t->chamfer = ch / n / 6.0;
    t->cycle2 = t->cycle3 = 0.0;
    for (int c = 0; c < NPAIR; c++) {
        const int *c2 = cc_cycle2[c], *c3 = cc_cycle3[c];
        double s2 = 0.0, s3 = 0.0;
        for (int b = 0; b < NB; b++)
            for (int m = 0; m < NP; m++) {
                int32_t n2 = f->idx1[c2[1]][b][m];
                int32_t n3 = f->idx1[c3[2]][b][f->idx1[c3[1]][b][m]];
                s2 += d2(def(r, c2[0], b) + 3 * n2, shape(r, c2[2], b) + 3 * m);
                s3 += d2(def(r, c3[0], b) + 3 * n3, shape(r, c3[3], b) + 3 * m);
            }
        t->rms2[c] = sqrt(s2 / (3 * n) + EPS), t->rms3[c] = sqrt(s3 / (3 * n) + EPS);
        t->cycle2 += t->rms2[c] / 6.0, t->cycle3 += t->rms3[c] / 6.0;
    }
}

/* ---- cases --------------------------------------------------------------- */

enum deform { NEAR_SOURCE, NEAR_TARGET, RANDOM };

typedef struct {
    float P[SZ_P], D[SZ_D];
} batch;

/* A triplet of similar shapes per batch entry (P2, P3 = P1 + noise), and
 * deformations near the identity, near a perfect fit, or unrelated random
 * points (many-to-one NN maps). */
static void make_batch(batch *x, enum deform kind, uint64_t seed)
{
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, seed, "test/cc/losses");
    for (int b = 0; b < NB; b++)
        for (int i = 0; i < NP * 3; i++) {
            double base = 2 * tcb_rng_uniform(&rng) - 1;
            for (int s = 0; s < 3; s++)
                x->P[((size_t)s * NB + b) * NP * 3 + i] =
                    (float)(base + (s ? 0.1 * tcb_rng_normal(&rng) : 0.0));
        }
    for (int k = 0; k < NPAIR; k++)
        for (int b = 0; b < NB; b++)
            for (int i = 0; i < NP * 3; i++) {
                int from = kind == NEAR_SOURCE ? cc_src[k] : cc_tgt[k];
                double v = kind == RANDOM ? 2 * tcb_rng_uniform(&rng) - 1
                                          : x->P[((size_t)(from - 1) * NB + b) * NP * 3 + i] +
                                                0.01 * tcb_rng_normal(&rng);
                x->D[((size_t)k * NB + b) * NP * 3 + i] = (float)v;
            }
}

static void to_ref(const batch *x, ref_case *r)
{
    for (int i = 0; i < SZ_P; i++) r->P[i] = x->P[i];
    for (int i = 0; i < SZ_D; i++) r->D[i] = x->D[i];
    ref_maps(r, &r->frozen);
}

static void eval(const batch *x, tcb_cc_loss_weights w, tcb_cc_loss_terms *t, float *gD)
{
    tcb_cc_losses *ws;
    tcb_error err = {0};
    assert_int_equal(tcb_cc_losses_create(NB, NP, &ws, &err), TCB_OK);
    int rc = tcb_cc_losses_eval(ws, x->P, x->D, NB, &w, t, gD, &err);
    if (rc) fail_msg("eval: %s", err.msg);
    tcb_cc_losses_free(ws);
}

static void expect_rel(double got, double want)
{
    assert_near(got, want, 1e-10 * fabs(want));
}

/* ---- tests --------------------------------------------------------------- */

static void test_pair_table(void **state)
{
    (void)state;
    const int want[NPAIR][2] = {{0, 1}, {1, 0}, {1, 2}, {2, 1}, {2, 0}, {0, 2}};
    for (int k = 0; k < NPAIR; k++) {
        assert_int_equal(tcb_cc_pairs[k][0], want[k][0]);
        assert_int_equal(tcb_cc_pairs[k][1], want[k][1]);
        assert_int_equal(tcb_cc_pairs[k][0], cc_src[k] - 1); /* CC's names agree */
        assert_int_equal(tcb_cc_pairs[k][1], cc_tgt[k] - 1);
        assert_int_equal(tcb_cc_pair_index(want[k][0], want[k][1]), k);
    }
    assert_int_equal(tcb_cc_pair_index(1, 1), -1);
    assert_int_equal(tcb_cc_pair_index(3, 0), -1);
    assert_int_equal(tcb_cc_pair_index(0, -1), -1);
}

static void check_values(enum deform kind, uint64_t seed)
{
    static batch x;
    static ref_case r;
    make_batch(&x, kind, seed);
    to_ref(&x, &r);
    ref_terms want;
    ref_eval(&r, &want);

    tcb_cc_losses *ws;
    tcb_error err = {0};
    assert_int_equal(tcb_cc_losses_create(NB + 1, NP, &ws, &err), TCB_OK); /* B < capacity */
    assert_null(tcb_cc_losses_matches(ws, 0));
    tcb_cc_loss_weights w = {0.7, 1.3, 0.4};
    tcb_cc_loss_terms got;
    assert_int_equal(tcb_cc_losses_eval(ws, x.P, x.D, NB, &w, &got, NULL, &err), TCB_OK);
    expect_rel(got.chamfer, want.chamfer);
    expect_rel(got.cycle2, want.cycle2);
    expect_rel(got.cycle3, want.cycle3);
    expect_rel(got.total, 0.7 * want.chamfer + 1.3 * want.cycle2 + 0.4 * want.cycle3);
    for (int k = 0; k < NPAIR; k++) {
        const int32_t *idx = tcb_cc_losses_matches(ws, k);
        assert_non_null(idx);
        assert_memory_equal(idx, r.frozen.idx1[k], sizeof r.frozen.idx1[k]);
    }
    assert_null(tcb_cc_losses_matches(ws, NPAIR));
    tcb_cc_losses_free(ws);
}

static void test_values(void **state)
{
    (void)state;
    check_values(NEAR_SOURCE, 1);
    check_values(NEAR_TARGET, 2);
    check_values(RANDOM, 3);
}

/* A by-hand case: B = N = 1, every cloud the origin and every D_k the
 * point (1, 0, 0). Chamfer: each target point is 1 away; cycle images are
 * (1,0,0) against (0,0,0): RMS = √(1/3 + ε). */
static void test_by_hand(void **state)
{
    (void)state;
    float P[9] = {0}, D[18] = {0};
    for (int k = 0; k < NPAIR; k++) D[3 * k] = 1.0f;
    tcb_cc_losses *ws;
    tcb_error err = {0};
    assert_int_equal(tcb_cc_losses_create(1, 1, &ws, &err), TCB_OK);
    tcb_cc_loss_weights w = {1, 1, 1};
    tcb_cc_loss_terms t;
    float g[18];
    assert_int_equal(tcb_cc_losses_eval(ws, P, D, 1, &w, &t, g, &err), TCB_OK);
    double rms = sqrt(1.0 / 3 + EPS);
    assert_near(t.chamfer, 1.0, 1e-15);
    assert_near(t.cycle2, rms, 1e-15);
    assert_near(t.cycle3, rms, 1e-15);
    assert_near(t.total, 1.0 + 2 * rms, 1e-15);
    /* ∂/∂x of each D_k: chamfer 1/6; cycle-2 and cycle-3 (one term each
     * gathers D_k) (1/6)·x/(3·rms) each. */
    for (int k = 0; k < NPAIR; k++) {
        assert_near(g[3 * k], 1.0 / 6 + 2 * (1.0 / 6) / (3 * rms), 1e-7);
        assert_true(g[3 * k + 1] == 0.0f && g[3 * k + 2] == 0.0f);
    }
    tcb_cc_losses_free(ws);
}

/* ---- gradients ----------------------------------------------------------- */

static void expect_grad(const float *an, const double *fd, int n)
{
    double scale = 0.0;
    for (int i = 0; i < n; i++) scale = fmax(scale, fabs(fd[i]));
    assert_true(scale > 0.0);
    for (int i = 0; i < n; i++)
        if (!(fabs(an[i] - fd[i]) <= 1e-5 * fabs(fd[i]) + 1e-6 * scale))
            fail_msg("entry %d: analytic %.9g, finite differences %.9g", i, an[i], fd[i]);
}

/* fd[t][i]: central differences of term t (chamfer, cycle2, cycle3) with
 * respect to D[i], indices frozen; each perturbation must leave the true
 * NN maps unchanged. */
static void frozen_fd(ref_case *r, double (*fd)[SZ_D])
{
    for (int i = 0; i < SZ_D; i++) {
        int k = i / (NB * NP * 3), b = i / (NP * 3) % NB;
        int32_t idx1[NP], idx2[NP];
        double keep = r->D[i], h = FD_REL * fmax(1.0, fabs(keep)), v[2][3];
        for (int side = 0; side < 2; side++) {
            r->D[i] = keep + (side ? -h : h);
            ref_terms t;
            ref_eval(r, &t);
            v[side][0] = t.chamfer, v[side][1] = t.cycle2, v[side][2] = t.cycle3;
            ref_maps_of(r, k, b, idx1, idx2);
            if (memcmp(idx1, r->frozen.idx1[k][b], sizeof idx1) ||
                memcmp(idx2, r->frozen.idx2[k][b], sizeof idx2))
                fail_msg("entry %d: a step of %g moves a nearest neighbour", i, h);
        }
        r->D[i] = keep;
        for (int t = 0; t < 3; t++) fd[t][i] = (v[0][t] - v[1][t]) / (2 * h);
    }
}

static void check_gradient(enum deform kind, uint64_t seed)
{
    static batch x;
    static ref_case r;
    static double fd[3][SZ_D], mix[SZ_D];
    static float g[SZ_D];
    make_batch(&x, kind, seed);
    to_ref(&x, &r);
    frozen_fd(&r, fd);
    tcb_cc_loss_terms t;
    const tcb_cc_loss_weights unit[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    for (int term = 0; term < 3; term++) {
        eval(&x, unit[term], &t, g);
        expect_grad(g, fd[term], SZ_D);
    }
    tcb_cc_loss_weights w = {0.7, 1.3, 0.4};
    for (int i = 0; i < SZ_D; i++) mix[i] = 0.7 * fd[0][i] + 1.3 * fd[1][i] + 0.4 * fd[2][i];
    eval(&x, w, &t, g);
    expect_grad(g, mix, SZ_D);
}

static void test_gradient_near_source(void **state)
{
    (void)state;
    check_gradient(NEAR_SOURCE, 11);
}

static void test_gradient_near_target(void **state)
{
    (void)state;
    check_gradient(NEAR_TARGET, 12);
}

static void test_gradient_random(void **state)
{
    (void)state;
    check_gradient(RANDOM, 13);
}

/* D_{0→1} = P_2 exactly: every target point sits on a deformed point, the
 * Chamfer term of that pair is 0 and so is its gradient (torch: NaN). */
static void test_chamfer_exact_fit(void **state)
{
    (void)state;
    static batch x;
    static ref_case r;
    static float g[SZ_D];
    make_batch(&x, RANDOM, 21);
    memcpy(x.D + (size_t)P2_P1 * NB * NP * 3, x.P + (size_t)1 * NB * NP * 3,
           sizeof(float) * NB * NP * 3);
    to_ref(&x, &r);
    ref_terms want;
    ref_eval(&r, &want);
    tcb_cc_loss_terms t;
    eval(&x, (tcb_cc_loss_weights){1, 0, 0}, &t, g);
    expect_rel(t.chamfer, want.chamfer);
    for (int i = 0; i < SZ_D; i++) assert_true(isfinite(g[i]));
    for (int i = 0; i < NB * NP * 3; i++) assert_true(g[(size_t)P2_P1 * NB * NP * 3 + i] == 0.0f);
}

/* The cycle terms pull only gathered points: with random D the maps are
 * many-to-one, so a gradient through the indices (or one that pulled the
 * first hop's points) would show outside the gathered set. Also Σ_n of the
 * gradient = Σ_m (image − start) / (6·3BN·RMS) per coordinate. */
static void check_support(int term, const tcb_cc_losses *ws, const ref_case *r, const float *g)
{
    ref_terms want;
    ref_eval(r, &want);
    for (int c = 0; c < NPAIR; c++) {
        int recv = term == 2 ? cc_cycle2[c][0] : cc_cycle3[c][0];
        int start = term == 2 ? cc_cycle2[c][2] : cc_cycle3[c][3];
        double rms = term == 2 ? want.rms2[c] : want.rms3[c];
        for (int b = 0; b < NB; b++) {
            int hit[NP] = {0}, hits = 0;
            double sum[3] = {0}, mag[3] = {0}, got[3] = {0};
            for (int m = 0; m < NP; m++) {
                int32_t n = tcb_cc_losses_matches(ws, term == 2 ? cc_cycle2[c][1]
                                                                : cc_cycle3[c][1])[b * NP + m];
                if (term == 3) n = tcb_cc_losses_matches(ws, cc_cycle3[c][2])[b * NP + n];
                hits += !hit[n], hit[n] = 1;
                for (int k = 0; k < 3; k++) {
                    double diff = def(r, recv, b)[3 * n + k] - shape(r, start, b)[3 * m + k];
                    sum[k] += diff / (6.0 * 3 * NB * NP * rms), mag[k] += fabs(diff);
                }
            }
            assert_true(hits < NP); /* the check has teeth */
            const float *gb = g + ((size_t)recv * NB + b) * NP * 3;
            for (int n = 0; n < NP; n++)
                for (int k = 0; k < 3; k++) {
                    if (!hit[n]) assert_true(gb[3 * n + k] == 0.0f);
                    got[k] += gb[3 * n + k];
                }
            for (int k = 0; k < 3; k++)
                assert_near(got[k], sum[k], 1e-6 * mag[k] / (6.0 * 3 * NB * NP * rms));
        }
    }
}

static void test_cycle_gradient_support(void **state)
{
    (void)state;
    static batch x;
    static ref_case r;
    static float g[SZ_D];
    make_batch(&x, RANDOM, 31);
    to_ref(&x, &r);
    tcb_cc_losses *ws;
    tcb_error err = {0};
    assert_int_equal(tcb_cc_losses_create(NB, NP, &ws, &err), TCB_OK);
    tcb_cc_loss_terms t;
    for (int term = 2; term <= 3; term++) {
        tcb_cc_loss_weights w = {0, term == 2, term == 3};
        assert_int_equal(tcb_cc_losses_eval(ws, x.P, x.D, NB, &w, &t, g, &err), TCB_OK);
        check_support(term, ws, &r, g);
    }
    tcb_cc_losses_free(ws);
}

/* ---- determinism, errors ------------------------------------------------- */

static void test_thread_count(void **state)
{
    (void)state;
    static batch x;
    static float g1[SZ_D], g2[SZ_D];
    make_batch(&x, RANDOM, 41);
    tcb_cc_loss_weights w = {1, 1, 1};
    tcb_cc_loss_terms t1, t2;
    int threads = omp_get_max_threads();
    omp_set_num_threads(1);
    eval(&x, w, &t1, g1);
    omp_set_num_threads(2);
    eval(&x, w, &t2, g2);
    omp_set_num_threads(threads);
    assert_memory_equal(&t1, &t2, sizeof t1);
    assert_memory_equal(g1, g2, sizeof g1);
}

static void expect_numeric(tcb_cc_losses *ws, const batch *x)
{
    static float g[SZ_D];
    for (int i = 0; i < SZ_D; i++) g[i] = 7.0f;
    tcb_cc_loss_terms t = {-1, -1, -1, -1};
    tcb_cc_loss_weights w = {1, 1, 1};
    tcb_error err = {0};
    assert_int_equal(tcb_cc_losses_eval(ws, x->P, x->D, NB, &w, &t, g, &err), TCB_ERR_NUMERIC);
    assert_true(err.msg[0] != '\0');
    assert_true(t.chamfer == -1 && t.total == -1);
    for (int i = 0; i < SZ_D; i++) assert_true(g[i] == 7.0f); /* untouched */
    assert_null(tcb_cc_losses_matches(ws, 0));
}

static void test_rejects(void **state)
{
    (void)state;
    static batch x;
    make_batch(&x, RANDOM, 51);
    tcb_cc_losses *ws = NULL;
    tcb_error err = {0};
    assert_int_equal(tcb_cc_losses_create(0, NP, &ws, &err), TCB_ERR_INPUT);
    assert_null(ws);
    assert_int_equal(tcb_cc_losses_create(NB, 0, &ws, &err), TCB_ERR_INPUT);
    assert_int_equal(tcb_cc_losses_create(NB, NP, &ws, &err), TCB_OK);
    tcb_cc_loss_weights w = {1, 1, 1};
    tcb_cc_loss_terms t;
    assert_int_equal(tcb_cc_losses_eval(ws, x.P, x.D, NB + 1, &w, &t, NULL, &err), TCB_ERR_INPUT);
    assert_int_equal(tcb_cc_losses_eval(ws, x.P, NULL, NB, &w, &t, NULL, &err), TCB_ERR_INPUT);
    assert_int_equal(tcb_cc_losses_eval(ws, x.P, x.D, NB, &w, &t, NULL, &err), TCB_OK);

    x.D[(size_t)3 * NB * NP * 3 + NP * 3 + 7] = NAN; /* pair 3, shape 1 */
    expect_numeric(ws, &x);
    make_batch(&x, RANDOM, 51);
    x.P[(size_t)2 * NB * NP * 3 + 5] = INFINITY;
    expect_numeric(ws, &x);
    tcb_cc_losses_free(ws); /* LSan: nothing else may be left behind */
    tcb_cc_losses_free(NULL);
}

/* ---- tcb_cc_rms ---------------------------------------------------------- */

static double ref_rms(const double *a, const float *b, int n)
{
    double s = 0.0;
    for (int i = 0; i < n; i++) s += (a[i] - b[i]) * (a[i] - b[i]);
    return sqrt(s / n + EPS);
}

static void test_rms(void **state)
{
    (void)state;
    enum { n = 50 };
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 61, "test/cc/rms");
    float a[n], b[n], g[n];
    double da[n], fd[n];
    for (int i = 0; i < n; i++) {
        a[i] = (float)tcb_rng_normal(&rng), b[i] = (float)tcb_rng_normal(&rng);
        da[i] = a[i];
    }
    double v = tcb_cc_rms(a, b, n, g);
    expect_rel(v, ref_rms(da, b, n));
    assert_true(tcb_cc_rms(a, b, n, NULL) == v);
    for (int i = 0; i < n; i++) {
        double keep = da[i], h = FD_REL * fmax(1.0, fabs(keep));
        da[i] = keep + h;
        double up = ref_rms(da, b, n);
        da[i] = keep - h;
        fd[i] = (up - ref_rms(da, b, n)) / (2 * h);
        da[i] = keep;
    }
    expect_grad(g, fd, n);
    /* a = b: √ε, zero gradient; nothing: 0 as CC's L2 returns. */
    assert_near(tcb_cc_rms(b, b, n, g), sqrt(EPS), 1e-18);
    for (int i = 0; i < n; i++) assert_true(g[i] == 0.0f);
    assert_true(tcb_cc_rms(a, b, 0, NULL) == 0.0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_pair_table),
        cmocka_unit_test(test_values),
        cmocka_unit_test(test_by_hand),
        cmocka_unit_test(test_gradient_near_source),
        cmocka_unit_test(test_gradient_near_target),
        cmocka_unit_test(test_gradient_random),
        cmocka_unit_test(test_chamfer_exact_fit),
        cmocka_unit_test(test_cycle_gradient_support),
        cmocka_unit_test(test_thread_count),
        cmocka_unit_test(test_rejects),
        cmocka_unit_test(test_rms),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
