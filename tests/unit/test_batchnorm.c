/* Checks of neural/batchnorm (BatchNorm1d over rows, PyTorch's train() and
 * eval()) against a naive double-precision reference written here: plain
 * loops, one channel at a time.
 *
 * Method as in test_atlas_grad.c: every float output is compared with the
 * reference (|f − d| ≤ 1e-5·max|d|); every gradient with central
 * differences of the reference objective L = Σ a·y (random a) in double,
 * step h = 1e-6·max(1, |θ|), and passes iff
 *     |g − fd| ≤ 1e-3·|fd| + 1e-5·max_T |g|
 * (max_T over the whole tensor). The thread check runs a size whose n·C
 * passes the parallel threshold (32768) with 1 and 2 OpenMP threads and
 * wants the same bits. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "neural/batchnorm.h"
#include "neural/layers.h"
#include "tcb/rng.h"
#include "testutil.h"

#define FD_H 1e-6
#define REL_TOL 1e-3
#define ABS_TOL 1e-5
#define FWD_TOL 1e-5

/* ---------------------------------------------------------------- helpers */

static double g_worst_fwd, g_worst_grad; /* the largest errors seen, as fractions of the tolerance */

static void check_forward(const char *what, const float *got, const double *want, size_t n)
{
    double scale = 0.0, worst = 0.0;
    for (size_t i = 0; i < n; i++) scale = fmax(scale, fabs(want[i]));
    for (size_t i = 0; i < n; i++) {
        double e = fabs(got[i] - want[i]);
        worst = fmax(worst, e / scale);
        if (!(e <= FWD_TOL * scale))
            fail_msg("%s[%zu] = %.9g, reference %.9g (scale %.3g)", what, i, got[i], want[i], scale);
    }
    g_worst_fwd = fmax(g_worst_fwd, worst / FWD_TOL);
    print_message("  %-28s max |f - d| / max|d| = %.2e\n", what, worst);
}

typedef double (*objective_fn)(void *ctx);

/* grad[0..n) against central differences of f in theta[0..n), every entry. */
static void check_grad(const char *what, objective_fn f, void *ctx, double *theta, const float *grad, size_t n)
{
    double gmax = 0.0, worst = 0.0, worst_rel = 0.0;
    for (size_t i = 0; i < n; i++) gmax = fmax(gmax, fabs(grad[i]));
    assert_true(gmax > 0.0); /* an all-zero gradient would check nothing */
    for (size_t i = 0; i < n; i++) {
        double t0 = theta[i], h = FD_H * fmax(1.0, fabs(t0));
        theta[i] = t0 + h;
        double fp = f(ctx);
        theta[i] = t0 - h;
        double fm = f(ctx);
        theta[i] = t0;
        double fd = (fp - fm) / (2.0 * h), e = fabs(grad[i] - fd), tol = REL_TOL * fabs(fd) + ABS_TOL * gmax;
        worst = fmax(worst, e / tol);
        if (fabs(fd) > 1e-2 * gmax) worst_rel = fmax(worst_rel, e / fabs(fd));
        if (!(e <= tol))
            fail_msg("%s[%zu]: analytic %.9g, finite difference %.9g (max |g| %.3g)", what, i, grad[i], fd, gmax);
    }
    g_worst_grad = fmax(g_worst_grad, worst);
    print_message("  %-28s %zu entries, max |g - fd|/|fd| = %.2e (%.2f of the tolerance)\n", what, n, worst_rel,
                  worst);
}

/* ------------------------------------------------ the double reference */

/* Training mode: y [n][C], and the batch mean and biased variance. */
static void ref_train(double *y, double *mu, double *var, const double *x, const double *gamma, const double *beta,
                      int n, int C)
{
    for (int c = 0; c < C; c++) {
        double m = 0.0, v = 0.0;
        for (int r = 0; r < n; r++) m += x[(size_t)r * C + c];
        m /= n;
        for (int r = 0; r < n; r++) v += (x[(size_t)r * C + c] - m) * (x[(size_t)r * C + c] - m);
        v /= n;
        if (mu) mu[c] = m, var[c] = v;
        for (int r = 0; r < n; r++)
            y[(size_t)r * C + c] = gamma[c] * (x[(size_t)r * C + c] - m) / sqrt(v + 1e-5) + beta[c];
    }
}

static void ref_eval(double *y, const double *x, const double *gamma, const double *beta, const double *rm,
                     const double *rv, int n, int C)
{
    for (int r = 0; r < n; r++)
        for (int c = 0; c < C; c++)
            y[(size_t)r * C + c] = gamma[c] * (x[(size_t)r * C + c] - rm[c]) / sqrt(rv[c] + 1e-5) + beta[c];
}

typedef struct {
    double *x, *gamma, *beta;
    const double *a;
    int n, C;
} bn_ctx;

static double bn_objective(void *p)
{
    bn_ctx *c = p;
    size_t len = (size_t)c->n * c->C;
    double *y = tu_dalloc(len), sum = 0.0;
    ref_train(y, NULL, NULL, c->x, c->gamma, c->beta, c->n, c->C);
    for (size_t i = 0; i < len; i++) sum += c->a[i] * y[i];
    free(y);
    return sum;
}

/* ---------------------------------------------------------------- layer */

/* A layer with its own parameter and buffer vectors. */
typedef struct {
    float params[2 * 512], buffers[2 * 512], grads[2 * 512];
    tcb_batchnorm bn, g;
} layer;

static void layer_make(layer *L, int C, tcb_rng *rng)
{
    assert_true(C <= 512);
    size_t po = 0, bo = 0, go = 0;
    tcb_batchnorm_bind(&L->bn, L->params, &po, L->buffers, &bo, C);
    tcb_batchnorm_bind(&L->g, L->grads, &go, NULL, NULL, C);
    assert_int_equal(po, 2 * C), assert_int_equal(bo, 2 * C), assert_int_equal(go, 2 * C);
    assert_ptr_equal(L->bn.beta, L->bn.gamma + C);
    assert_ptr_equal(L->bn.var, L->bn.mean + C);
    assert_null(L->g.mean), assert_null(L->g.var);
    tcb_batchnorm_reset_running(&L->bn);
    for (int c = 0; c < C; c++) assert_true(L->bn.mean[c] == 0.0f && L->bn.var[c] == 1.0f);
    tu_fill_uniform(rng, L->bn.gamma, C, 0.5, 1.5);
    tu_fill_uniform(rng, L->bn.beta, C, -0.5, 0.5);
    memset(L->grads, 0, sizeof L->grads);
}

/* Inputs with a different offset and spread per channel; channel 1 has a
 * mean 20× its spread, as a layer with a large bias gives. */
static void fill_input(tcb_rng *rng, float *x, int n, int C)
{
    for (int c = 0; c < C; c++) {
        double off = c == 1 ? 2.0 : 2.0 * tcb_rng_uniform(rng) - 1.0, sd = c == 1 ? 0.1 : 0.2 + tcb_rng_uniform(rng);
        for (int r = 0; r < n; r++) x[(size_t)r * C + c] = (float)(off + sd * (2.0 * tcb_rng_uniform(rng) - 1.0));
    }
}

/* Training forward, running statistics, eval forward and backward of one
 * layer over n rows of C channels (C > 64: two column chunks, the second
 * partial). */
static void check_layer(int n, int C, tcb_rng *rng)
{
    print_message(" n = %d, C = %d\n", n, C);
    size_t len = (size_t)n * C;
    layer L;
    layer_make(&L, C, rng);
    float *x = tu_falloc(len), *y = tu_falloc(len), *xhat = tu_falloc(len), *a = tu_falloc(len), *dx = tu_falloc(len);
    float rstd[512], mu[512], var2[512];
    fill_input(rng, x, n, C);
    tu_fill_uniform(rng, a, len, -1, 1);

    /* training forward */
    tcb_batchnorm_forward_train(&L.bn, y, xhat, rstd, mu, var2, x, n, 0);
    bn_ctx c = {tu_to_double(x, len), tu_to_double(L.bn.gamma, C), tu_to_double(L.bn.beta, C), tu_to_double(a, len), n, C};
    double *yref = tu_dalloc(len), *xhref = tu_dalloc(len), one[512], zero[512], muref[512], varref[512], rsref[512];
    for (int k = 0; k < C; k++) one[k] = 1.0, zero[k] = 0.0;
    ref_train(yref, muref, varref, c.x, c.gamma, c.beta, n, C);
    ref_train(xhref, NULL, NULL, c.x, one, zero, n, C);
    for (int k = 0; k < C; k++) rsref[k] = 1.0 / sqrt(varref[k] + 1e-5);
    check_forward("train y", y, yref, len);
    check_forward("train x-hat", xhat, xhref, len);
    check_forward("train batch mean", mu, muref, C);
    check_forward("train biased variance", var2, varref, C);
    check_forward("train rstd", rstd, rsref, C);
    /* in place (y aliasing x) gives the same bits */
    float *yy = tu_falloc(len);
    memcpy(yy, x, len * sizeof(float));
    tcb_batchnorm_forward_train(&L.bn, yy, xhat, rstd, mu, var2, yy, n, 0);
    assert_memory_equal(yy, y, len * sizeof(float));
    free(yy);

    /* the running statistics, from random ones: momentum 0.1, the variance
     * unbiased by n/(n − 1) */
    tu_fill_uniform(rng, L.bn.mean, C, -1, 1);
    tu_fill_uniform(rng, L.bn.var, C, 0.5, 2);
    double rm[512], rv[512], want_m[512], want_v[512];
    for (int k = 0; k < C; k++) {
        rm[k] = L.bn.mean[k], rv[k] = L.bn.var[k];
        want_m[k] = 0.9 * rm[k] + 0.1 * muref[k];
        want_v[k] = 0.9 * rv[k] + 0.1 * varref[k] * n / (n - 1.0);
    }
    tcb_batchnorm_update_running(&L.bn, mu, var2, n);
    check_forward("running mean", L.bn.mean, want_m, C);
    check_forward("running variance", L.bn.var, want_v, C);

    /* eval forward with those running statistics; in place too */
    for (int k = 0; k < C; k++) rm[k] = L.bn.mean[k], rv[k] = L.bn.var[k];
    tcb_batchnorm_forward_eval(&L.bn, y, x, n, 0);
    ref_eval(yref, c.x, c.gamma, c.beta, rm, rv, n, C);
    check_forward("eval y", y, yref, len);
    yy = tu_falloc(len);
    memcpy(yy, x, len * sizeof(float));
    tcb_batchnorm_forward_eval(&L.bn, yy, yy, n, 0);
    assert_memory_equal(yy, y, len * sizeof(float));
    for (int k = 0; k < C; k++) assert_true(L.bn.mean[k] == (float)rm[k] && L.bn.var[k] == (float)rv[k]);
    free(yy);

    /* backward of L = Σ a·y through the training forward */
    tcb_batchnorm_forward_train(&L.bn, y, xhat, rstd, mu, var2, x, n, 0);
    tcb_batchnorm_backward(&L.bn, &L.g, dx, a, NULL, xhat, rstd, n);
    check_grad("dx", bn_objective, &c, c.x, dx, len);
    check_grad("dgamma", bn_objective, &c, c.gamma, L.g.gamma, C);
    check_grad("dbeta", bn_objective, &c, c.beta, L.g.beta, C);

    /* dx aliasing dy: the same bits; dγ, dβ accumulate (now doubled) */
    float *dd = tu_falloc(len), g0 = L.g.gamma[0], b0 = L.g.beta[C - 1];
    memcpy(dd, a, len * sizeof(float));
    tcb_batchnorm_backward(&L.bn, &L.g, dd, dd, NULL, xhat, rstd, n);
    assert_memory_equal(dd, dx, len * sizeof(float));
    assert_near(L.g.gamma[0], 2.0f * g0, 1e-6 * fabs(g0));
    assert_near(L.g.beta[C - 1], 2.0f * b0, 1e-6 * fabs(b0));

    free(x), free(y), free(xhat), free(a), free(dx), free(dd), free(yref), free(xhref);
    free(c.x), free(c.gamma), free(c.beta), free((void *)c.a);
}

static void test_layer(void **state)
{
    (void)state;
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 1, "test/batchnorm/layer");
    check_layer(9, 70, &rng); /* two column chunks, the second of 6 */
    check_layer(2, 5, &rng);  /* the fewest rows training allows: unbias ×2 */
    check_layer(3, 64, &rng); /* one full chunk, three rows (the predictor's batch) */
    print_message(" worst: forward %.2f, gradient %.2f of the tolerance\n", g_worst_fwd, g_worst_grad);
}

/* A mean far above the spread (|μ|/σ = 1e3): x̂ must still be accurate. */
static void test_offset_input(void **state)
{
    (void)state;
    enum { n = 16, C = 4 };
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 1, "test/batchnorm/offset");
    layer L;
    layer_make(&L, C, &rng);
    float x[n * C], y[n * C], xhat[n * C], rstd[C], mu[C], var2[C];
    for (int r = 0; r < n; r++)
        for (int c = 0; c < C; c++) x[r * C + c] = (float)(100.0 * (c + 1) + 0.1 * (2.0 * tcb_rng_uniform(&rng) - 1.0));
    tcb_batchnorm_forward_train(&L.bn, y, xhat, rstd, mu, var2, x, n, 0);
    double *xd = tu_to_double(x, n * C), *gd = tu_to_double(L.bn.gamma, C), *bd = tu_to_double(L.bn.beta, C);
    double yref[n * C], muref[C], varref[C];
    ref_train(yref, muref, varref, xd, gd, bd, n, C);
    check_forward("offset train y", y, yref, n * C);
    check_forward("offset biased variance", var2, varref, C);
    /* eval with running statistics of that kind */
    double rm[C], rv[C];
    for (int c = 0; c < C; c++) {
        L.bn.mean[c] = (float)(100.0 * (c + 1) + 0.01), L.bn.var[c] = 2e-3f;
        rm[c] = L.bn.mean[c], rv[c] = L.bn.var[c];
    }
    tcb_batchnorm_forward_eval(&L.bn, y, x, n, 0);
    ref_eval(yref, xd, gd, bd, rm, rv, n, C);
    check_forward("offset eval y", y, yref, n * C);
    free(xd), free(gd), free(bd);
}

/* The fused ReLU: forward_train / forward_eval with relu give exactly
 * max(0, ·) of the plain outputs (x̂ and the statistics unchanged), and the
 * backward given the fused output y equals the plain backward of dy masked
 * by y > 0. The inputs straddle zero, so both sides of the kink occur. */
static void test_fused_relu(void **state)
{
    (void)state;
    enum { n = 40, C = 24 };
    size_t len = (size_t)n * C;
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 1, "test/batchnorm/relu");
    layer L;
    layer_make(&L, C, &rng);
    float *x = tu_falloc(len), *a = tu_falloc(len), *y = tu_falloc(len), *yr = tu_falloc(len), *xh = tu_falloc(len),
          *xhr = tu_falloc(len), *dx = tu_falloc(len), *dxr = tu_falloc(len), *masked = tu_falloc(len);
    float st[3][C], str[3][C];
    fill_input(&rng, x, n, C);
    tu_fill_uniform(&rng, a, len, -1, 1);
    tcb_batchnorm_forward_train(&L.bn, y, xh, st[0], st[1], st[2], x, n, 0);
    tcb_batchnorm_forward_train(&L.bn, yr, xhr, str[0], str[1], str[2], x, n, 1);
    int zeros = 0;
    for (size_t i = 0; i < len; i++) {
        assert_true(yr[i] == (y[i] > 0 ? y[i] : 0.0f));
        zeros += yr[i] == 0.0f;
        masked[i] = yr[i] > 0 ? a[i] : 0.0f;
    }
    assert_true(zeros > 0 && zeros < (int)len);
    assert_memory_equal(xh, xhr, len * sizeof(float));
    assert_memory_equal(st, str, sizeof st);
    float *ye = tu_falloc(len), *yer = tu_falloc(len);
    tcb_batchnorm_forward_eval(&L.bn, ye, x, n, 0);
    tcb_batchnorm_forward_eval(&L.bn, yer, x, n, 1);
    for (size_t i = 0; i < len; i++) assert_true(yer[i] == (ye[i] > 0 ? ye[i] : 0.0f));
    free(ye), free(yer);
    float g1[2 * C], g2[2 * C];
    memset(L.grads, 0, sizeof L.grads);
    tcb_batchnorm_backward(&L.bn, &L.g, dx, masked, NULL, xh, st[0], n);
    memcpy(g1, L.grads, sizeof g1);
    memset(L.grads, 0, sizeof L.grads);
    tcb_batchnorm_backward(&L.bn, &L.g, dxr, a, yr, xh, st[0], n);
    memcpy(g2, L.grads, sizeof g2);
    assert_memory_equal(dx, dxr, len * sizeof(float));
    assert_memory_equal(g1, g2, sizeof g1);
    free(x), free(a), free(y), free(yr), free(xh), free(xhr), free(dx), free(dxr), free(masked);
}

/* n·C = 300·200 = 60,000 > 32,768: the OpenMP path runs (4 column chunks,
 * the last of 8). 1 and 2 threads must give the same bits everywhere. */
static void test_threads(void **state)
{
    (void)state;
    enum { n = 300, C = 200 };
    size_t len = (size_t)n * C;
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 1, "test/batchnorm/threads");
    layer L;
    layer_make(&L, C, &rng);
    float *x = tu_falloc(len), *a = tu_falloc(len);
    fill_input(&rng, x, n, C);
    tu_fill_uniform(&rng, a, len, -1, 1);
    float *out[2][4]; /* per thread count: y, xhat, eval y, dx */
    float st[2][5][C], bufs[2][2 * C], grads[2][2 * C];
    float b0[2 * C];
    memcpy(b0, L.buffers, sizeof b0);
    int prev = omp_get_max_threads();
    for (int t = 0; t < 2; t++) {
        omp_set_num_threads(t + 1);
        assert_int_equal(omp_get_max_threads(), t + 1);
        for (int k = 0; k < 4; k++) out[t][k] = tu_falloc(len);
        memcpy(L.buffers, b0, sizeof b0);
        memset(L.grads, 0, sizeof L.grads);
        tcb_batchnorm_forward_train(&L.bn, out[t][0], out[t][1], st[t][0], st[t][1], st[t][2], x, n, 0);
        tcb_batchnorm_update_running(&L.bn, st[t][1], st[t][2], n);
        tcb_batchnorm_forward_eval(&L.bn, out[t][2], x, n, 0);
        memcpy(out[t][3], a, len * sizeof(float));
        tcb_batchnorm_backward(&L.bn, &L.g, out[t][3], out[t][3], NULL, out[t][1], st[t][0], n);
        memcpy(bufs[t], L.buffers, sizeof bufs[t]);
        memcpy(grads[t], L.grads, sizeof grads[t]);
    }
    omp_set_num_threads(prev);
    for (int k = 0; k < 4; k++) assert_memory_equal(out[0][k], out[1][k], len * sizeof(float));
    assert_memory_equal(st[0], st[1], 3 * C * sizeof(float));
    assert_memory_equal(bufs[0], bufs[1], sizeof bufs[0]);
    assert_memory_equal(grads[0], grads[1], sizeof grads[0]);

    /* and the chunked parallel forward is right at this size */
    double *xd = tu_to_double(x, len), *gd = tu_to_double(L.bn.gamma, C), *bd = tu_to_double(L.bn.beta, C);
    double *yref = tu_dalloc(len), muref[C], varref[C];
    ref_train(yref, muref, varref, xd, gd, bd, n, C);
    check_forward("parallel train y", out[1][0], yref, len);
    check_forward("parallel biased variance", st[1][2], varref, C);
    free(xd), free(gd), free(bd), free(yref);
    for (int t = 0; t < 2; t++)
        for (int k = 0; k < 4; k++) free(out[t][k]);
    free(x), free(a);
}

/* The fused batch norm and max-pool (PointNet's last layer) against the
 * two layers it fuses, bit for bit, with 1 and 2 threads: forward_train
 * then tcb_maxpool_forward, and the backward of dg scattered to the max
 * rows. nb = 5 sets of n = 90 rows: the reductions' four row blocks
 * (boundaries 112, 225, 337) cut through sets; R·C = 36,000 takes the
 * parallel path. Every third channel's γ is negative (the max comes from
 * the smallest x), the inputs sit 100 above their spread (the mean's low
 * part matters) and take 12 levels a channel, so ties in the max occur
 * and the first row must win. */
static void test_fused_maxpool(void **state)
{
    (void)state;
    enum { nb = 5, n = 90, C = 80, R = nb * n };
    size_t len = (size_t)R * C;
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 1, "test/batchnorm/maxpool");
    layer L;
    layer_make(&L, C, &rng);
    for (int c = 0; c < C; c += 3) L.bn.gamma[c] = -L.bn.gamma[c];
    float *x = tu_falloc(len), *y = tu_falloc(len), *xh = tu_falloc(len), *d = tu_falloc(len);
    float *dx = tu_falloc(len);
    for (size_t i = 0; i < len; i++) x[i] = 100.0f + (float)floor(12.0 * tcb_rng_uniform(&rng)) / 12.0f;
    float dg[nb * C], g[nb * C], gf[nb * C], st[3][C], sf[4][C];
    int32_t arg[nb * C], argf[nb * C];
    tu_fill_uniform(&rng, dg, nb * C, -1, 1);
    /* the unfused layers */
    tcb_batchnorm_forward_train(&L.bn, y, xh, st[0], st[1], st[2], x, R, 0);
    tcb_maxpool_forward(g, arg, y, nb, n, C);
    int ties = 0; /* rows other than the kept one that reach the max: the first must win */
    for (int b = 0; b < nb; b++)
        for (int j = 0; j < C; j++)
            for (int i = 0; i < n; i++) ties += i != arg[b * C + j] && y[((size_t)b * n + i) * C + j] == g[b * C + j];
    assert_true(ties > 0);
    memset(d, 0, len * sizeof(float));
    for (int b = 0; b < nb; b++)
        for (int j = 0; j < C; j++) d[((size_t)b * n + arg[b * C + j]) * C + j] = dg[b * C + j];
    tcb_batchnorm_backward(&L.bn, &L.g, d, d, NULL, xh, st[0], R);
    float gref[2 * C];
    memcpy(gref, L.grads, sizeof gref);
    int prev = omp_get_max_threads();
    for (int t = 1; t <= 2; t++) {
        omp_set_num_threads(t);
        memset(L.grads, 0, sizeof L.grads);
        tcb_batchnorm_maxpool_forward_train(&L.bn, gf, argf, sf[0], sf[1], sf[2], sf[3], x, nb, n);
        tcb_batchnorm_maxpool_backward(&L.bn, &L.g, dx, dg, argf, x, sf[0], sf[1], sf[2], nb, n);
        assert_memory_equal(gf, g, sizeof g);
        assert_memory_equal(argf, arg, sizeof arg);
        assert_memory_equal(sf[0], st[0], 2 * C * sizeof(float)); /* rstd, mean */
        assert_memory_equal(sf[3], st[2], C * sizeof(float));     /* variance */
        assert_memory_equal(dx, d, len * sizeof(float));
        assert_memory_equal(L.grads, gref, sizeof gref);
    }
    omp_set_num_threads(prev);
    free(x), free(y), free(xh), free(d), free(dx);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_layer),
        cmocka_unit_test(test_offset_input),
        cmocka_unit_test(test_fused_relu),
        cmocka_unit_test(test_threads),
        cmocka_unit_test(test_fused_maxpool),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
