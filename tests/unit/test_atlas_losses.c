/* Atlas losses (Chamfer, metric consistency, DSR): values against naive
 * double-precision implementations written here from the protocol's
 * formulas, analytic gradients against central finite differences of those
 * naive implementations, and hand-computed tiny cases.
 *
 * Gradient tolerance, per entry: |analytic − FD| ≤ 1e-3·|FD| + 1e-4·max|FD|
 * (1e-3 relative, with a floor for entries near zero). Values: 1e-6
 * relative. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "methods/atlas/loss_chamfer.h"
#include "methods/atlas/loss_dsr.h"
#include "methods/atlas/loss_metric.h"
#include "tcb/rng.h"
#include "testutil.h"

#define B 4
#define M 20
#define N 15
#define FD_H 1e-6
#define WEIGHT 0.7f
#define PREFILL 0.5f /* gradients must be accumulated onto what is there */

/* ---- naive references, double precision, straight from the formulas ---- */

static double d2(const double *a, const double *b)
{
    return (a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
           (a[2] - b[2]) * (a[2] - b[2]);
}

static double min_d2(const double *q, const double *set, int n)
{
    double best = INFINITY;
    for (int j = 0; j < n; j++) best = fmin(best, d2(q, set + 3 * j));
    return best;
}

/* pred [nb][m][3], target [nb][n][3]. */
static double ref_chamfer(const double *pred, const double *target, int nb, int m, int n)
{
    double s1 = 0.0, s2 = 0.0;
    for (int b = 0; b < nb; b++) {
        const double *p = pred + (size_t)b * m * 3, *t = target + (size_t)b * n * 3;
        for (int i = 0; i < m; i++) s1 += min_d2(p + 3 * i, t, n);
        for (int j = 0; j < n; j++) s2 += min_d2(t + 3 * j, p, m);
    }
    return s1 / (nb * m) + s2 / (nb * n);
}

static void fff(const double *pu, const double *pv, double *e, double *f, double *g)
{
    *e = *f = *g = 0.0;
    for (int c = 0; c < 3; c++) *e += pu[c] * pu[c], *f += pu[c] * pv[c], *g += pv[c] * pv[c];
}

static double ref_metric(const double *pu, const double *pv, int nb, int m)
{
    double sum = 0.0;
    for (int pair = 0; pair < nb / 2; pair++)
        for (int i = 0; i < m; i++) {
            size_t a = ((size_t)(2 * pair) * m + i) * 3, b = a + (size_t)m * 3;
            double ea, fa, ga, eb, fb, gb;
            fff(pu + a, pv + a, &ea, &fa, &ga);
            fff(pu + b, pv + b, &eb, &fb, &gb);
            sum += (ea - eb) * (ea - eb) + 2 * (fa - fb) * (fa - fb) + (ga - gb) * (ga - gb);
        }
    return sum / (nb / 2 * m);
}

/* Everything read from the inputs in the naive DSR, for the tests' benefit. */
typedef struct {
    int nb, m, p;
    const double *area_gt;
    tcb_atlas_dsr_weights w;
} dsr_case;

/* Σ_p mean_{samples∈p} A of one shape. */
static double ref_total_area(const double *pu, const double *pv, int m, int p)
{
    int per = m / p;
    double total = 0.0, e, f, g;
    for (int k = 0; k < p; k++) {
        double mean_a = 0.0;
        for (int s = 0; s < per; s++) {
            size_t i = ((size_t)k * per + s) * 3;
            fff(pu + i, pv + i, &e, &f, &g);
            mean_a += sqrt(fmax(e * g - f * f, 0.0)) / per;
        }
        total += mean_a;
    }
    return total;
}

static double ref_dsr(const double *pu, const double *pv, const dsr_case *c,
                      tcb_atlas_dsr_terms *t)
{
    int k = c->nb * c->m;
    double mu_e = 0.0, mu_g = 0.0, e, f, g;
    for (int i = 0; i < k; i++) {
        fff(pu + 3 * i, pv + 3 * i, &e, &f, &g);
        mu_e += e / k, mu_g += g / k;
    }
    *t = (tcb_atlas_dsr_terms){0};
    for (int i = 0; i < k; i++) {
        fff(pu + 3 * i, pv + 3 * i, &e, &f, &g);
        double a2 = fmax(e * g - f * f, 0.0), den = a2 + 1e-20;
        t->e += (e - mu_e) * (e - mu_e) / den / k;
        t->g += (g - mu_g) * (g - mu_g) / den / k;
        t->skew += f * f / den / k;
        t->stretch += (e - g) * (e - g) / den / k;
    }
    for (int b = 0; b < c->nb; b++) {
        size_t o = (size_t)b * c->m * 3;
        double over = fmax(0.0, ref_total_area(pu + o, pv + o, c->m, c->p) - c->area_gt[b]);
        t->total_area += over * over / c->nb;
    }
    return c->w.e * t->e + c->w.g * t->g + c->w.skew * t->skew + c->w.stretch * t->stretch +
           c->w.total_area * t->total_area;
}

/* ---- helpers ----------------------------------------------------------- */

static void to_double(const float *x, double *out, int n)
{
    for (int i = 0; i < n; i++) out[i] = x[i];
}

static void fill(float *x, int n, float v)
{
    for (int i = 0; i < n; i++) x[i] = v;
}

/* Analytic gradient (acc − PREFILL)/WEIGHT against the FD gradient fd. */
static void expect_grad(const float *acc, const double *fd, int n)
{
    double scale = 0.0;
    for (int i = 0; i < n; i++) scale = fmax(scale, fabs(fd[i]));
    assert_true(scale > 0.0);
    for (int i = 0; i < n; i++) {
        double an = ((double)acc[i] - PREFILL) / WEIGHT;
        if (!(fabs(an - fd[i]) <= 1e-3 * fabs(fd[i]) + 1e-4 * scale))
            fail_msg("entry %d: analytic %.9g, finite differences %.9g", i, an, fd[i]);
    }
}

/* Central differences of f over x[0..n), f reading x through ctx. */
typedef double (*scalar_fn)(void *ctx);

static void central_diff(scalar_fn fn, void *ctx, double *x, int n, double *fd)
{
    for (int i = 0; i < n; i++) {
        double keep = x[i];
        x[i] = keep + FD_H;
        double up = fn(ctx);
        x[i] = keep - FD_H;
        double down = fn(ctx);
        x[i] = keep;
        fd[i] = (up - down) / (2 * FD_H);
    }
}

static void random_fill(tcb_rng *rng, float *x, int n, double lo, double hi)
{
    for (int i = 0; i < n; i++) x[i] = (float)(lo + (hi - lo) * tcb_rng_uniform(rng));
}

/* Tangents near an orthonormal frame, scaled per shape so that μ_E, μ_G
 * and the total area differ between shapes; A² stays well above 0. */
static void random_tangents(tcb_rng *rng, float *pu, float *pv, int nb, int m)
{
    for (int b = 0; b < nb; b++) {
        double s = 0.6 + 0.3 * b;
        for (int i = 0; i < m; i++)
            for (int c = 0; c < 3; c++) {
                size_t k = ((size_t)b * m + i) * 3 + c;
                pu[k] = (float)(s * ((c == 0) + 0.3 * (2 * tcb_rng_uniform(rng) - 1)));
                pv[k] = (float)(s * ((c == 1) + 0.3 * (2 * tcb_rng_uniform(rng) - 1)));
            }
    }
}

/* ---- Chamfer ---------------------------------------------------------- */

typedef struct {
    double *pred, *target;
} chamfer_ctx;

static double chamfer_fn(void *ctx)
{
    chamfer_ctx *c = ctx;
    return ref_chamfer(c->pred, c->target, B, M, N);
}

static void test_chamfer_random(void **state)
{
    (void)state;
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 1, "test/atlas/chamfer");
    float pred[B * M * 3], target[B * N * 3], grad[B * M * 3];
    random_fill(&rng, pred, B * M * 3, -1.0, 1.0);
    random_fill(&rng, target, B * N * 3, -1.0, 1.0);
    fill(grad, B * M * 3, PREFILL);
    tcb_error err = {0};
    double loss;
    assert_int_equal(tcb_atlas_chamfer_loss(pred, target, B, M, N, WEIGHT, &loss, grad, &err),
                     TCB_OK);

    double dpred[B * M * 3], dtarget[B * N * 3], fd[B * M * 3];
    to_double(pred, dpred, B * M * 3);
    to_double(target, dtarget, B * N * 3);
    double ref = ref_chamfer(dpred, dtarget, B, M, N);
    assert_near(loss, ref, 1e-6 * ref);
    chamfer_ctx ctx = {dpred, dtarget};
    central_diff(chamfer_fn, &ctx, dpred, B * M * 3, fd);
    expect_grad(grad, fd, B * M * 3);

    /* Without a gradient buffer: the same loss. */
    double again;
    assert_int_equal(tcb_atlas_chamfer_loss(pred, target, B, M, N, WEIGHT, &again, NULL, &err),
                     TCB_OK);
    assert_true(again == loss);
}

/* One predicted point above the first of two targets, by hand:
 * p̂→p: 0.25; p→p̂: (0.25 + 1.25)/2; L = 1. ∂/∂p̂ = (0,0,1) + [(0,0,1) + (−2,0,1)]/2. */
static void test_chamfer_by_hand(void **state)
{
    (void)state;
    const float target[] = {0, 0, 0, 1, 0, 0}, pred[] = {0, 0, 0.5f};
    float grad[3] = {0};
    double loss;
    tcb_error err = {0};
    assert_int_equal(tcb_atlas_chamfer_loss(pred, target, 1, 1, 2, 1.0f, &loss, grad, &err),
                     TCB_OK);
    assert_true(loss == 1.0);
    assert_true(grad[0] == -1.0f && grad[1] == 0.0f && grad[2] == 2.0f);

    /* A perfect fit: zero loss, zero gradient. */
    float fit_grad[6] = {0};
    assert_int_equal(tcb_atlas_chamfer_loss(target, target, 1, 2, 2, 1.0f, &loss, fit_grad, &err),
                     TCB_OK);
    assert_true(loss == 0.0);
    for (int i = 0; i < 6; i++) assert_true(fit_grad[i] == 0.0f);
}

static void test_chamfer_rejects(void **state)
{
    (void)state;
    const float target[] = {0, 0, 0}, bad[] = {0, NAN, 0};
    double loss;
    tcb_error err = {0};
    assert_int_equal(tcb_atlas_chamfer_loss(target, target, 1, 0, 1, 1.0f, &loss, NULL, &err),
                     TCB_ERR_INPUT);
    assert_int_equal(tcb_atlas_chamfer_loss(bad, target, 1, 1, 1, 1.0f, &loss, NULL, &err),
                     TCB_ERR_NUMERIC);
}

/* ---- metric consistency ----------------------------------------------- */

typedef struct {
    double *pu, *pv;
} tangents_ctx;

static double metric_fn(void *ctx)
{
    tangents_ctx *c = ctx;
    return ref_metric(c->pu, c->pv, B, M);
}

static void test_metric_random(void **state)
{
    (void)state;
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 2, "test/atlas/metric");
    float pu[B * M * 3], pv[B * M * 3], gu[B * M * 3], gv[B * M * 3];
    random_tangents(&rng, pu, pv, B, M);
    fill(gu, B * M * 3, PREFILL), fill(gv, B * M * 3, PREFILL);
    tcb_error err = {0};
    double loss;
    assert_int_equal(tcb_atlas_metric_loss(pu, pv, B, M, WEIGHT, &loss, gu, gv, &err), TCB_OK);

    double du[B * M * 3], dv[B * M * 3], fd[B * M * 3];
    to_double(pu, du, B * M * 3), to_double(pv, dv, B * M * 3);
    double ref = ref_metric(du, dv, B, M);
    assert_near(loss, ref, 1e-6 * ref);
    tangents_ctx ctx = {du, dv};
    central_diff(metric_fn, &ctx, du, B * M * 3, fd);
    expect_grad(gu, fd, B * M * 3);
    central_diff(metric_fn, &ctx, dv, B * M * 3, fd);
    expect_grad(gv, fd, B * M * 3);
}

/* (x, y, z) → (−y, x, z) is an exact rotation in float, so shape b is an
 * exact isometric copy of shape a: zero loss, exactly zero gradient. */
static void test_metric_isometric_pair(void **state)
{
    (void)state;
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 3, "test/atlas/metric/iso");
    float pu[2 * M * 3], pv[2 * M * 3], gu[2 * M * 3] = {0}, gv[2 * M * 3] = {0};
    random_tangents(&rng, pu, pv, 1, M);
    for (int i = 0; i < M; i++) {
        float *u = pu + 3 * i, *v = pv + 3 * i, *ru = u + 3 * M, *rv = v + 3 * M;
        ru[0] = -u[1], ru[1] = u[0], ru[2] = u[2];
        rv[0] = -v[1], rv[1] = v[0], rv[2] = v[2];
    }
    tcb_error err = {0};
    double loss;
    assert_int_equal(tcb_atlas_metric_loss(pu, pv, 2, M, 1.0f, &loss, gu, gv, &err), TCB_OK);
    assert_true(loss == 0.0);
    for (int i = 0; i < 2 * M * 3; i++) assert_true(gu[i] == 0.0f && gv[i] == 0.0f);
}

/* φ_u stretched ×2 in shape b: ΔE = 1 − 4 = −3, e = 9 = L;
 * ∂L/∂E_a = 2ΔE = −6 → ∂L/∂φu_a = −6·2φu_a; ∂L/∂φu_b = +6·2φu_b. */
static void test_metric_by_hand(void **state)
{
    (void)state;
    const float pu[] = {1, 0, 0, 2, 0, 0}, pv[] = {0, 1, 0, 0, 1, 0};
    float gu[6] = {0}, gv[6] = {0};
    tcb_error err = {0};
    double loss;
    assert_int_equal(tcb_atlas_metric_loss(pu, pv, 2, 1, 1.0f, &loss, gu, gv, &err), TCB_OK);
    assert_true(loss == 9.0);
    const float want_u[] = {-12, 0, 0, 24, 0, 0};
    for (int i = 0; i < 6; i++) assert_true(gu[i] == want_u[i] && gv[i] == 0.0f);
    assert_int_equal(tcb_atlas_metric_loss(pu, pv, 3, 1, 1.0f, &loss, gu, gv, &err),
                     TCB_ERR_INPUT);
}

/* ---- DSR ---------------------------------------------------------------- */

typedef struct {
    double *pu, *pv;
    const dsr_case *c;
} dsr_ctx;

static double dsr_fn(void *ctx)
{
    dsr_ctx *d = ctx;
    tcb_atlas_dsr_terms t;
    return ref_dsr(d->pu, d->pv, d->c, &t);
}

/* Random tangents; area_gt puts shapes 0 and 2 over their GT area (L_Atot
 * active) and 1 and 3 under it (inactive). */
static void check_dsr_random(int p, tcb_atlas_dsr_weights w, uint64_t seed)
{
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, seed, "test/atlas/dsr");
    float pu[B * M * 3], pv[B * M * 3], gu[B * M * 3], gv[B * M * 3];
    random_tangents(&rng, pu, pv, B, M);
    fill(gu, B * M * 3, PREFILL), fill(gv, B * M * 3, PREFILL);
    double du[B * M * 3], dv[B * M * 3], fd[B * M * 3], area_gt[B] = {0};
    to_double(pu, du, B * M * 3), to_double(pv, dv, B * M * 3);

    for (int b = 0; b < B; b++)
        area_gt[b] = ref_total_area(du + (size_t)b * M * 3, dv + (size_t)b * M * 3, M, p) *
                     (b % 2 ? 1.1 : 0.9);

    dsr_case c = {B, M, p, area_gt, w};
    tcb_atlas_dsr_terms got, want;
    double loss, ref = ref_dsr(du, dv, &c, &want);
    tcb_error err = {0};
    assert_int_equal(tcb_atlas_dsr_loss(pu, pv, B, M, p, area_gt, &w, WEIGHT, &loss, &got, gu,
                                        gv, &err),
                     TCB_OK);
    assert_near(loss, ref, 1e-6 * ref);
    assert_near(got.e, want.e, 1e-6 * want.e);
    assert_near(got.g, want.g, 1e-6 * want.g);
    assert_near(got.skew, want.skew, 1e-6 * want.skew);
    assert_near(got.stretch, want.stretch, 1e-6 * want.stretch);
    assert_near(got.total_area, want.total_area, 1e-6 * want.total_area);
    assert_true(want.total_area > 0.0);

    dsr_ctx ctx = {du, dv, &c};
    central_diff(dsr_fn, &ctx, du, B * M * 3, fd);
    expect_grad(gu, fd, B * M * 3);
    central_diff(dsr_fn, &ctx, dv, B * M * 3, fd);
    expect_grad(gv, fd, B * M * 3);
}

static void test_dsr_random(void **state)
{
    (void)state;
    tcb_atlas_dsr_weights w = tcb_atlas_dsr_defaults();
    assert_true(w.e == 1 && w.g == 1 && w.skew == 1 && w.stretch == 0 && w.total_area == 100);
    check_dsr_random(2, w, 4);
    w.stretch = 0.5; /* off in TCSR, but its gradient must be right too */
    check_dsr_random(4, w, 5);
}

/* The flat square φ(u, v) = (s u, s v, 0): E = G = s², F = 0, A = s², so
 * every isometry term vanishes. With s = 1/2, P = 2: Σ_p mean A = 1/2.
 * Shape 0 has area_gt 1/4 (excess 1/4), shape 1 has 1 (none):
 * L_Atot = (1/16 + 0)/2, L = 100/32. ∂L/∂A_i = 100·(2/B)·(1/4)·(P/M) = 12.5
 * in shape 0, and ∂A/∂φu = (Gφu − Fφv)/A = φu/s·s = (1/2, 0, 0). */
static void test_dsr_flat_square(void **state)
{
    (void)state;
    enum { NB = 2, NM = 4, NP = 2 };
    float pu[NB * NM * 3] = {0}, pv[NB * NM * 3] = {0}, gu[NB * NM * 3] = {0},
          gv[NB * NM * 3] = {0};
    for (int i = 0; i < NB * NM; i++) pu[3 * i] = 0.5f, pv[3 * i + 1] = 0.5f;
    const double area_gt[NB] = {0.25, 1.0};
    tcb_atlas_dsr_weights w = tcb_atlas_dsr_defaults();
    tcb_atlas_dsr_terms t;
    double loss;
    tcb_error err = {0};
    assert_int_equal(tcb_atlas_dsr_loss(pu, pv, NB, NM, NP, area_gt, &w, 1.0f, &loss, &t, gu,
                                        gv, &err),
                     TCB_OK);
    assert_true(t.e == 0 && t.g == 0 && t.skew == 0 && t.stretch == 0);
    assert_true(t.total_area == 1.0 / 32 && loss == 100.0 / 32);
    for (int i = 0; i < NB * NM; i++) {
        float want = i < NM ? 6.25f : 0.0f;
        assert_true(gu[3 * i] == want && gu[3 * i + 1] == 0 && gu[3 * i + 2] == 0);
        assert_true(gv[3 * i] == 0 && gv[3 * i + 1] == want && gv[3 * i + 2] == 0);
    }
}

/* A sample with φ_v = 2φ_u has EG − F² = 0 exactly: no gradient through
 * A there (torch would give NaN or inf), finite gradients everywhere. */
static void test_dsr_degenerate_sample(void **state)
{
    (void)state;
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 6, "test/atlas/dsr/degenerate");
    float pu[B * M * 3], pv[B * M * 3], gu[B * M * 3] = {0}, gv[B * M * 3] = {0};
    random_tangents(&rng, pu, pv, B, M);
    for (int c = 0; c < 3; c++) pv[c] = 2.0f * pu[c];
    const double area_gt[B] = {0, 0, 0, 0}; /* L_Atot active everywhere */
    tcb_atlas_dsr_weights area_only = {.total_area = 100.0};
    double loss;
    tcb_error err = {0};
    assert_int_equal(tcb_atlas_dsr_loss(pu, pv, B, M, 2, area_gt, &area_only, 1.0f, &loss, NULL,
                                        gu, gv, &err),
                     TCB_OK);
    for (int c = 0; c < 3; c++) assert_true(gu[c] == 0.0f && gv[c] == 0.0f);
    assert_true(gu[3] != 0.0f);

    tcb_atlas_dsr_weights w = tcb_atlas_dsr_defaults();
    assert_int_equal(tcb_atlas_dsr_loss(pu, pv, B, M, 2, area_gt, &w, 1.0f, &loss, NULL, gu, gv,
                                        &err),
                     TCB_OK);
    for (int i = 0; i < B * M * 3; i++) assert_true(isfinite(gu[i]) && isfinite(gv[i]));
}

static void test_dsr_rejects(void **state)
{
    (void)state;
    float pu[6] = {1, 0, 0, 1, 0, 0}, pv[6] = {0, 1, 0, 0, NAN, 0};
    const double area_gt[1] = {0};
    tcb_atlas_dsr_weights w = tcb_atlas_dsr_defaults();
    double loss;
    tcb_error err = {0};
    assert_int_equal(tcb_atlas_dsr_loss(pu, pv, 1, 2, 3, area_gt, &w, 1.0f, &loss, NULL, NULL,
                                        NULL, &err),
                     TCB_ERR_INPUT);
    assert_int_equal(tcb_atlas_dsr_loss(pu, pv, 1, 2, 1, area_gt, &w, 1.0f, &loss, NULL, NULL,
                                        NULL, &err),
                     TCB_ERR_NUMERIC);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_chamfer_random),
        cmocka_unit_test(test_chamfer_by_hand),
        cmocka_unit_test(test_chamfer_rejects),
        cmocka_unit_test(test_metric_random),
        cmocka_unit_test(test_metric_isometric_pair),
        cmocka_unit_test(test_metric_by_hand),
        cmocka_unit_test(test_dsr_random),
        cmocka_unit_test(test_dsr_flat_square),
        cmocka_unit_test(test_dsr_degenerate_sample),
        cmocka_unit_test(test_dsr_rejects),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
