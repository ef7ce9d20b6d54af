/* Gradient checks of the atlas network (methods/atlas/{layers,encoder,
 * decoder,model}.c) against a naive double-precision reference written here:
 * plain loops, one sample at a time, forward-mode tangents per sample, no
 * stacking, no GEMM, layer 1 unsplit.
 *
 * Method: every forward is compared with the reference (float vs double,
 * |f − d| ≤ 1e-5·max|d|); every gradient with central differences of the
 * reference objective in double, step h = 1e-6·max(1, |θ|) (truncation
 * ~h² and rounding ~1e-16/h are both ≪ the tolerance), and passes iff
 *     |g − fd| ≤ 1e-3·|fd| + 1e-5·max_T |g|
 * where max_T is over the whole tensor (the floor covers entries that are
 * small by cancellation, where float rounding is relatively larger). The
 * objective L = Σ a·φ + Σ b·φ_u + Σ c·φ_v with random a, b, c exercises the
 * reverse mode through the tangents, softplus′′ included. The shared
 * layers of neural/ are checked here too (Linear, ReLU, LeakyReLU: the
 * last is neupig's MLP's). */
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

#include "methods/atlas/model.h"
#include "testutil.h"

#define FD_H 1e-6
#define REL_TOL 1e-3
#define ABS_TOL 1e-5
#define FWD_TOL 1e-5
#define MAXW 128 /* widest layer output of the test networks */

/* Small sizes: C = 16 gives decoder widths 18 → 9 → 4 → 3, so the GEMM path
 * (9 → 4) and the fused tiny path (4 → 3) both run. */
enum { C = 16, P = 2, B = 2, N = 32, M = 14, MP = M / P };

/* ---------------------------------------------------------------- helpers */

static void check_forward(const char *what, const float *got, const double *want, size_t n)
{
    double scale = 0.0;
    for (size_t i = 0; i < n; i++) scale = fmax(scale, fabs(want[i]));
    for (size_t i = 0; i < n; i++)
        if (!(fabs(got[i] - want[i]) <= FWD_TOL * scale))
            fail_msg("%s[%zu] = %.9g, reference %.9g (scale %.3g)", what, i, got[i], want[i],
                     scale);
}

typedef double (*objective_fn)(void *ctx);

/* grad[0..n) is the analytic gradient of f w.r.t. theta[0..n); checks `count`
 * entries (all when n ≤ count, else the first, the last and random ones). */
static void check_grad(const char *what, objective_fn f, void *ctx, double *theta,
                       const float *grad, size_t n, int count, tcb_rng *rng)
{
    double gmax = 0.0;
    for (size_t i = 0; i < n; i++) gmax = fmax(gmax, fabs(grad[i]));
    assert_true(gmax > 0.0); /* an all-zero gradient would check nothing */
    int k = n <= (size_t)count ? (int)n : count;
    for (int s = 0; s < k; s++) {
        size_t i = n <= (size_t)count ? (size_t)s
                   : s == 0             ? 0
                   : s == 1             ? n - 1
                                        : tcb_rng_below(rng, (uint32_t)n);
        double t0 = theta[i], h = FD_H * fmax(1.0, fabs(t0));
        theta[i] = t0 + h;
        double fp = f(ctx);
        theta[i] = t0 - h;
        double fm = f(ctx);
        theta[i] = t0;
        double fd = (fp - fm) / (2.0 * h);
        if (!(fabs(grad[i] - fd) <= REL_TOL * fabs(fd) + ABS_TOL * gmax))
            fail_msg("%s[%zu]: analytic %.9g, finite difference %.9g (max |g| %.3g)", what, i,
                     grad[i], fd, gmax);
    }
}

/* ------------------------------------------------ the double reference */

static double ref_softplus(double s) { return s > 20.0 ? s : log1p(exp(s)); }
static double ref_sigmoid(double s) { return s > 20.0 ? 1.0 : 1.0 / (1.0 + exp(-s)); }

typedef struct {
    const double *W, *b;
    int in, out;
} ref_layer;

/* The double view of a float layer l of model m, inside pd (same layout). */
static ref_layer ref_view(const tcb_atlas_model *m, const double *pd, const tcb_linear *l)
{
    return (ref_layer){pd + (l->W - m->params), pd + (l->b - m->params), l->in, l->out};
}

/* y = W x (+ b if with_bias). */
static void ref_affine(double *y, ref_layer L, const double *x, int with_bias)
{
    for (int o = 0; o < L.out; o++) {
        double s = with_bias ? L.b[o] : 0.0;
        for (int k = 0; k < L.in; k++) s += L.W[(size_t)o * L.in + k] * x[k];
        y[o] = s;
    }
}

/* clouds [nb][n][3] → z [nb][C], one point at a time. */
static void ref_encode(const tcb_atlas_model *m, const double *pd, const double *clouds, int nb,
                       int n, double *z)
{
    ref_layer L[TCB_ATLAS_ENC_LAYERS];
    for (int k = 0; k < TCB_ATLAS_ENC_LAYERS; k++) L[k] = ref_view(m, pd, &m->enc.l[k]);
    double h1[64], h2[128], h3[MAXW], g[MAXW], f1[MAXW];
    for (int b = 0; b < nb; b++) {
        for (int c = 0; c < m->C; c++) g[c] = -INFINITY;
        for (int i = 0; i < n; i++) {
            ref_affine(h1, L[0], clouds + ((size_t)b * n + i) * 3, 1);
            for (int j = 0; j < 64; j++) h1[j] = fmax(h1[j], 0.0);
            ref_affine(h2, L[1], h1, 1);
            for (int j = 0; j < 128; j++) h2[j] = fmax(h2[j], 0.0);
            ref_affine(h3, L[2], h2, 1);
            for (int c = 0; c < m->C; c++) g[c] = fmax(g[c], h3[c]);
        }
        ref_affine(f1, L[3], g, 1);
        for (int c = 0; c < m->C; c++) f1[c] = fmax(f1[c], 0.0);
        ref_affine(z + (size_t)b * m->C, L[4], f1, 1);
        for (int c = 0; c < m->C; c++) z[b * m->C + c] = fmax(z[b * m->C + c], 0.0);
    }
}

/* Decoder p at (u, v, z): out[0] = φ, out[1] = φ_u, out[2] = φ_v, by
 * forward-mode tangents through the unsplit MLP on x = [u, v, z]. */
static void ref_decode(const tcb_atlas_model *m, const double *pd, int p, const double *z,
                       double u, double v, double out[3][3])
{
    double x[3][MAXW], s[3][MAXW]; /* value, ∂/∂u, ∂/∂v */
    int h = m->C + 2;
    for (int j = 0; j < h; j++) {
        x[0][j] = j == 0 ? u : j == 1 ? v : z[j - 2];
        x[1][j] = j == 0;
        x[2][j] = j == 1;
    }
    for (int k = 0; k < TCB_ATLAS_DEC_LAYERS; k++) {
        ref_layer L = ref_view(m, pd, &m->dec[p].l[k]);
        for (int t = 0; t < 3; t++) ref_affine(s[t], L, x[t], t == 0);
        for (int j = 0; j < L.out; j++) {
            if (k == TCB_ATLAS_DEC_LAYERS - 1) {
                for (int t = 0; t < 3; t++) out[t][j] = s[t][j];
                continue;
            }
            double sig = ref_sigmoid(s[0][j]);
            x[0][j] = ref_softplus(s[0][j]);
            x[1][j] = sig * s[1][j];
            x[2][j] = sig * s[2][j];
        }
    }
}

/* ------------------------------------------------------------- layers */

typedef struct {
    double *x, *W, *b; /* x [(1+nt)·n][in] */
    const double *w;   /* objective weights [(1+nt)·n][out] */
    int n, nt, in, out;
} lin_ctx;

static double lin_objective(void *p)
{
    lin_ctx *c = p;
    ref_layer L = {c->W, c->b, c->in, c->out};
    double y[MAXW], sum = 0.0;
    for (int r = 0; r < (1 + c->nt) * c->n; r++) {
        ref_affine(y, L, c->x + (size_t)r * c->in, r < c->n);
        for (int o = 0; o < c->out; o++) sum += c->w[(size_t)r * c->out + o] * y[o];
    }
    return sum;
}

/* One linear layer over n value rows and 2 tangent blocks. */
static void check_linear(int n, int in, int out, tcb_rng *rng)
{
    int rows = 3 * n;
    float *x = tu_falloc((size_t)rows * in), *W = tu_falloc((size_t)out * in), *b = tu_falloc(out);
    float *y = tu_falloc((size_t)rows * out), *w = tu_falloc((size_t)rows * out);
    float *dx = tu_falloc((size_t)rows * in), *dW = tu_falloc((size_t)out * in), *db = tu_falloc(out);
    tu_fill_uniform(rng, x, (size_t)rows * in, -1, 1);
    tu_fill_uniform(rng, W, (size_t)out * in, -1, 1);
    tu_fill_uniform(rng, b, out, -1, 1);
    tu_fill_uniform(rng, w, (size_t)rows * out, -1, 1);
    lin_ctx c = {tu_to_double(x, (size_t)rows * in), tu_to_double(W, (size_t)out * in),
                 tu_to_double(b, out), tu_to_double(w, (size_t)rows * out), n, 2, in, out};

    tcb_linear_forward(y, x, W, b, n, 2, in, out);
    double *yref = malloc((size_t)rows * out * sizeof(double));
    ref_layer L = {c.W, c.b, in, out};
    for (int r = 0; r < rows; r++) ref_affine(yref + (size_t)r * out, L, c.x + (size_t)r * in, r < n);
    check_forward("linear y", y, yref, (size_t)rows * out);

    tcb_linear_backward(dx, dW, db, w, x, W, n, 2, in, out);
    check_grad("linear dW", lin_objective, &c, c.W, dW, (size_t)out * in, 24, rng);
    check_grad("linear db", lin_objective, &c, c.b, db, out, 24, rng);
    check_grad("linear dx", lin_objective, &c, c.x, dx, (size_t)rows * in, 24, rng);

    /* accumulation: a second backward doubles dW and db */
    float dW0 = dW[1], db0 = db[0];
    tcb_linear_backward(NULL, dW, db, w, x, W, n, 2, in, out);
    assert_near(dW[1], 2.0f * dW0, 1e-6 * fabs(dW0));
    assert_near(db[0], 2.0f * db0, 1e-6 * fabs(db0));

    free(x), free(W), free(b), free(y), free(w), free(dx), free(dW), free(db), free(yref);
    free(c.x), free(c.W), free(c.b), free((void *)c.w);
}

static void test_linear(void **state)
{
    (void)state;
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 1, "test/atlas/linear");
    check_linear(5, 7, 6, &rng);  /* sgemm */
    check_linear(5, 3, 6, &rng);  /* fused: the xyz input */
    check_linear(5, 3, 70, &rng); /* fused, several column chunks */
    check_linear(5, 6, 3, &rng);  /* fused: the xyz output */
    check_linear(40, 70, 3, &rng); /* fused, several column chunks */
}

/* A product large enough to be cut into row blocks, one per thread
 * (neural/layers.c, sgemm_rows), with an odd row count so the blocks differ
 * in size: y and dx at one thread and at two against the double reference
 * (a block's rows or its offsets wrong show there). */
static void test_linear_threads(void **state)
{
    (void)state;
    enum { rows = 1001, in = 100, out = 70 };
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 1, "test/atlas/linear_threads");
    float *x = tu_falloc((size_t)rows * in), *W = tu_falloc((size_t)out * in), *b = tu_falloc(out);
    float *dy = tu_falloc((size_t)rows * out), *dW = tu_falloc((size_t)out * in);
    float *y[2] = {tu_falloc((size_t)rows * out), tu_falloc((size_t)rows * out)};
    float *dx[2] = {tu_falloc((size_t)rows * in), tu_falloc((size_t)rows * in)};
    tu_fill_uniform(&rng, x, (size_t)rows * in, -1, 1);
    tu_fill_uniform(&rng, W, (size_t)out * in, -1, 1);
    tu_fill_uniform(&rng, b, out, -1, 1);
    tu_fill_uniform(&rng, dy, (size_t)rows * out, -1, 1);
    int prev = omp_get_max_threads();
    for (int t = 0; t < 2; t++) {
        omp_set_num_threads(t + 1);
        tcb_linear_forward(y[t], x, W, b, rows, 0, in, out);
        tcb_linear_backward(dx[t], dW, NULL, dy, x, W, rows, 0, in, out);
    }
    omp_set_num_threads(prev);

    double *xd = tu_to_double(x, (size_t)rows * in), *Wd = tu_to_double(W, (size_t)out * in);
    double *bd = tu_to_double(b, out), *ref = malloc((size_t)rows * (out > in ? out : in) * sizeof(double));
    ref_layer L = {Wd, bd, in, out};
    for (int r = 0; r < rows; r++) ref_affine(ref + (size_t)r * out, L, xd + (size_t)r * in, 1);
    check_forward("linear y, 1 thread", y[0], ref, (size_t)rows * out);
    check_forward("split linear y", y[1], ref, (size_t)rows * out);
    for (int r = 0; r < rows; r++)
        for (int i = 0; i < in; i++) {
            double s = 0;
            for (int o = 0; o < out; o++) s += (double)dy[(size_t)r * out + o] * Wd[(size_t)o * in + i];
            ref[(size_t)r * in + i] = s;
        }
    check_forward("linear dx, 1 thread", dx[0], ref, (size_t)rows * in);
    check_forward("split linear dx", dx[1], ref, (size_t)rows * in);

    free(x), free(W), free(b), free(dy), free(dW), free(y[0]), free(y[1]), free(dx[0]), free(dx[1]);
    free(xd), free(Wd), free(bd), free(ref);
}

typedef struct {
    double *x;
    const double *w;
    int n;
    double slope; /* 0: ReLU; > 0: LeakyReLU */
} relu_ctx;

static double relu_objective(void *p)
{
    relu_ctx *c = p;
    double sum = 0.0;
    for (int i = 0; i < c->n; i++) sum += c->w[i] * (c->x[i] > 0 ? c->x[i] : c->slope * c->x[i]);
    return sum;
}

/* ReLU (slope 0, the atlas decoders) and LeakyReLU (neupig's MLP, slope
 * 0.01): forward exact, backward against central differences. */
static void check_relu(float slope)
{
    enum { n = 64 };
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 1, "test/atlas/relu");
    float x[n], y[n], w[n], dx[n];
    tu_fill_uniform(&rng, x, n, -1, 1);
    tu_fill_uniform(&rng, w, n, -1, 1);
    if (slope > 0) tcb_leaky_relu_forward(y, x, n, slope);
    else tcb_relu_forward(y, x, n);
    relu_ctx c = {tu_to_double(x, n), tu_to_double(w, n), n, slope};
    for (int i = 0; i < n; i++) assert_true(y[i] == (x[i] > 0 ? x[i] : slope * x[i]));
    if (slope > 0) tcb_leaky_relu_backward(dx, w, y, n, slope);
    else tcb_relu_backward(dx, w, y, n);
    check_grad(slope > 0 ? "leaky relu dx" : "relu dx", relu_objective, &c, c.x, dx, n, n, &rng);
    free(c.x), free((void *)c.w);
}

static void test_relu(void **state)
{
    (void)state;
    check_relu(0.0f);
}

static void test_leaky_relu(void **state)
{
    (void)state;
    check_relu(0.01f);
}

typedef struct {
    double *x; /* [3·n][d] */
    const double *w;
    int n, d;
} sp_ctx;

static void ref_softplus_stack(const double *x, double *y, int n, int d)
{
    size_t blk = (size_t)n * d;
    for (size_t i = 0; i < blk; i++) {
        y[i] = ref_softplus(x[i]);
        for (int t = 1; t <= 2; t++) y[t * blk + i] = ref_sigmoid(x[i]) * x[t * blk + i];
    }
}

static double sp_objective(void *p)
{
    sp_ctx *c = p;
    size_t len = 3 * (size_t)c->n * c->d;
    double *y = malloc(len * sizeof(double)), sum = 0.0;
    ref_softplus_stack(c->x, y, c->n, c->d);
    for (size_t i = 0; i < len; i++) sum += c->w[i] * y[i];
    free(y);
    return sum;
}

static void test_softplus(void **state)
{
    (void)state;
    enum { n = 6, d = 5, len = 3 * n * d };
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 1, "test/atlas/softplus");
    float x[len], y[len], w[len], dx[len];
    tu_fill_uniform(&rng, x, len, -4, 4);
    tu_fill_uniform(&rng, w, len, -1, 1);
    x[0] = 25.0f;  /* linear branch: softplus′ = 1, softplus′′ = 0 */
    x[1] = -30.0f; /* deep in the exponential tail */
    x[2] = 19.5f;  /* just below the threshold */
    tcb_softplus_forward(y, x, n, 2, d);
    sp_ctx c = {tu_to_double(x, len), tu_to_double(w, len), n, d};
    double yref[len];
    ref_softplus_stack(c.x, yref, n, d);
    check_forward("softplus y", y, yref, len);
    assert_true(y[0] == 25.0f && y[n * d] == x[n * d]);
    tcb_softplus_backward(dx, w, x, n, 2, d);
    check_grad("softplus dx", sp_objective, &c, c.x, dx, len, len, &rng);
    /* in place, as the decoder may call it */
    memcpy(y, w, sizeof y);
    tcb_softplus_backward(y, y, x, n, 2, d);
    assert_memory_equal(y, dx, sizeof y);
    free(c.x), free((void *)c.w);
}

typedef struct {
    double *x, *W, *b; /* x [nb][n][in] */
    const double *w;   /* [nb][out] */
    int nb, n, in, out;
} pool_ctx;

/* Σ w · maxpool(x·Wᵀ + b) */
static double pool_objective(void *p)
{
    pool_ctx *c = p;
    ref_layer L = {c->W, c->b, c->in, c->out};
    double sum = 0.0, y[MAXW];
    for (int b = 0; b < c->nb; b++) {
        double mx[MAXW];
        for (int o = 0; o < c->out; o++) mx[o] = -INFINITY;
        for (int i = 0; i < c->n; i++) {
            ref_affine(y, L, c->x + ((size_t)b * c->n + i) * c->in, 1);
            for (int o = 0; o < c->out; o++) mx[o] = fmax(mx[o], y[o]);
        }
        for (int o = 0; o < c->out; o++) sum += c->w[b * c->out + o] * mx[o];
    }
    return sum;
}

static void test_maxpool(void **state)
{
    (void)state;
    enum { nb = 3, n = 9, in = 4, out = 5 };
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 1, "test/atlas/maxpool");
    float h[nb * n * out], y[nb * out];
    int32_t arg[nb * out];
    tu_fill_uniform(&rng, h, nb * n * out, -1, 1);
    h[4 * out] = h[7 * out] = 5.0f; /* a tie in set 0, channel 0: the first point wins */
    tcb_maxpool_forward(y, arg, h, nb, n, out);
    assert_int_equal(arg[0], 4);
    for (int b = 0; b < nb; b++)
        for (int j = 0; j < out; j++) {
            float mx = -INFINITY;
            for (int i = 0; i < n; i++) mx = fmaxf(mx, h[(b * n + i) * out + j]);
            assert_true(y[b * out + j] == mx && h[(b * n + arg[b * out + j]) * out + j] == mx);
        }

    /* linear + pool backward against differences of the composed function */
    float x[nb * n * in], W[out * in], bias[out], w[nb * out];
    float dx[nb * n * in], dW[out * in] = {0}, db[out] = {0};
    tu_fill_uniform(&rng, x, nb * n * in, -1, 1);
    tu_fill_uniform(&rng, W, out * in, -1, 1);
    tu_fill_uniform(&rng, bias, out, -1, 1);
    tu_fill_uniform(&rng, w, nb * out, -1, 1);
    tcb_linear_forward(h, x, W, bias, nb * n, 0, in, out);
    tcb_maxpool_forward(y, arg, h, nb, n, out);
    tcb_maxpool_linear_backward(dx, dW, db, w, arg, x, W, nb, n, in, out);
    pool_ctx c = {tu_to_double(x, nb * n * in), tu_to_double(W, out * in), tu_to_double(bias, out),
                  tu_to_double(w, nb * out), nb, n, in, out};
    check_grad("pooled linear dW", pool_objective, &c, c.W, dW, out * in, out * in, &rng);
    check_grad("pooled linear db", pool_objective, &c, c.b, db, out, out, &rng);
    check_grad("pooled linear dx", pool_objective, &c, c.x, dx, nb * n * in, nb * n * in, &rng);
    free(c.x), free(c.W), free(c.b), free((void *)c.w);
}

/* ------------------------------------------------------------ decoder */

static tcb_atlas_model *make_model(uint64_t seed)
{
    tcb_atlas_model *m;
    tcb_error err = {0};
    assert_int_equal(tcb_atlas_model_create(C, P, &m, &err), TCB_OK);
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, seed, "test/atlas/init");
    tcb_atlas_model_init(m, &rng);
    return m;
}

typedef struct {
    const tcb_atlas_model *m;
    double *pd;   /* parameters */
    double *z;    /* [B][C] */
    double *uv;   /* [MP][2] */
    const double *coef; /* [3][B][MP][3] stacked objective weights */
} dec_ctx;

static double dec_objective(void *p)
{
    dec_ctx *c = p;
    double sum = 0.0;
    for (int b = 0; b < B; b++)
        for (int i = 0; i < MP; i++) {
            double out[3][3];
            ref_decode(c->m, c->pd, 0, c->z + b * C, c->uv[2 * i], c->uv[2 * i + 1], out);
            for (int k = 0; k < 3; k++)
                for (int j = 0; j < 3; j++)
                    sum += c->coef[(((size_t)k * B + b) * MP + i) * 3 + j] * out[k][j];
        }
    return sum;
}

typedef struct {
    tcb_atlas_model *m;
    tcb_atlas_decoder_cache cache;
    tcb_atlas_decoder_scratch scratch;
    float z[B * C], uv[MP * 2], out[3 * B * MP * 3], coef[3 * B * MP * 3];
} dec_fixture;

static void dec_setup(dec_fixture *f, tcb_rng *rng)
{
    tcb_error err = {0};
    f->m = make_model(11);
    assert_int_equal(tcb_atlas_decoder_cache_alloc(&f->cache, B, MP, C, &err), TCB_OK);
    assert_int_equal(tcb_atlas_decoder_scratch_alloc(&f->scratch, B, MP, C, &err), TCB_OK);
    tu_fill_uniform(rng, f->z, B * C, 0, 2); /* latent codes come out of a ReLU */
    tu_fill_uniform(rng, f->uv, MP * 2, 0, 1);
    tu_fill_uniform(rng, f->coef, 3 * B * MP * 3, -1, 1);
}

static void dec_teardown(dec_fixture *f)
{
    tcb_atlas_decoder_cache_free(&f->cache);
    tcb_atlas_decoder_scratch_free(&f->scratch);
    tcb_atlas_model_free(f->m);
}

/* φ, φ_u, φ_v against the reference, and φ_u, φ_v against central
 * differences of the reference φ in u and v. */
static void test_decoder_tangents(void **state)
{
    (void)state;
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 1, "test/atlas/tangents");
    dec_fixture f;
    dec_setup(&f, &rng);
    tcb_atlas_decoder_forward(&f.m->dec[0], &f.cache, f.z, f.uv, 2, f.out);
    double *pd = tu_to_double(f.m->params, f.m->nparams), *zd = tu_to_double(f.z, B * C);
    double ref[3 * B * MP * 3], fd[2 * B * MP * 3];
    const double h = 1e-5;
    for (int b = 0; b < B; b++)
        for (int i = 0; i < MP; i++) {
            double out[3][3], hi[3][3], lo[3][3], u = f.uv[2 * i], v = f.uv[2 * i + 1];
            ref_decode(f.m, pd, 0, zd + b * C, u, v, out);
            for (int k = 0; k < 3; k++)
                for (int j = 0; j < 3; j++) ref[(((size_t)k * B + b) * MP + i) * 3 + j] = out[k][j];
            for (int t = 0; t < 2; t++) {
                ref_decode(f.m, pd, 0, zd + b * C, u + (t == 0) * h, v + (t == 1) * h, hi);
                ref_decode(f.m, pd, 0, zd + b * C, u - (t == 0) * h, v - (t == 1) * h, lo);
                for (int j = 0; j < 3; j++)
                    fd[(((size_t)t * B + b) * MP + i) * 3 + j] = (hi[0][j] - lo[0][j]) / (2 * h);
            }
        }
    check_forward("decoder out", f.out, ref, 3 * B * MP * 3);
    /* the tangent rows against differences of φ: error O(h²) + O(1e-16/h) */
    check_forward("decoder tangents vs differences", f.out + B * MP * 3, fd, 2 * B * MP * 3);
    free(pd), free(zd);
    dec_teardown(&f);
}

static void check_decoder_grad(int nt)
{
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 1 + nt, "test/atlas/decoder");
    dec_fixture f;
    dec_setup(&f, &rng);
    if (!nt) memset(f.coef + B * MP * 3, 0, 2 * B * MP * 3 * sizeof(float));
    tcb_atlas_decoder_forward(&f.m->dec[0], &f.cache, f.z, f.uv, 2, f.out);
    float dz[B * C] = {0}, duv[MP * 2] = {0};
    tcb_atlas_decoder_backward(&f.m->dec[0], &f.m->gdec[0], &f.cache, &f.scratch, f.z, f.uv,
                               f.coef, nt, dz, duv);
    dec_ctx c = {f.m, tu_to_double(f.m->params, f.m->nparams), tu_to_double(f.z, B * C),
                 tu_to_double(f.uv, MP * 2), tu_to_double(f.coef, 3 * B * MP * 3)};
    for (int k = 0; k < TCB_ATLAS_DEC_LAYERS; k++) {
        const tcb_linear *l = &f.m->dec[0].l[k], *g = &f.m->gdec[0].l[k];
        char what[64];
        snprintf(what, sizeof what, "decoder fc%d.weight (nt=%d)", k + 1, nt);
        check_grad(what, dec_objective, &c, c.pd + (l->W - f.m->params), g->W,
                   (size_t)l->in * l->out, 12, &rng);
        snprintf(what, sizeof what, "decoder fc%d.bias (nt=%d)", k + 1, nt);
        check_grad(what, dec_objective, &c, c.pd + (l->b - f.m->params), g->b, l->out, 8, &rng);
    }
    /* layer 1's uv columns, whose gradient has the tangent term */
    const tcb_linear *l1 = &f.m->dec[0].l[0];
    for (int col = 0; col < 2; col++)
        for (int r = 0; r < l1->out; r += 5) {
            size_t at = (size_t)r * l1->in + col;
            check_grad("decoder fc1.weight uv column", dec_objective, &c,
                       c.pd + (l1->W - f.m->params) + at, f.m->gdec[0].l[0].W + at, 1, 1, &rng);
        }
    check_grad("decoder dz", dec_objective, &c, c.z, dz, B * C, B * C, &rng);
    check_grad("decoder duv", dec_objective, &c, c.uv, duv, MP * 2, MP * 2, &rng);
    free(c.pd), free(c.z), free(c.uv), free((void *)c.coef);
    dec_teardown(&f);
}

static void test_decoder_grad(void **state)
{
    (void)state;
    check_decoder_grad(2);
    check_decoder_grad(0); /* no tangent gradient: the tangent rows are skipped */
}

/* ------------------------------------------------------------ encoder */

typedef struct {
    const tcb_atlas_model *m;
    double *pd;
    const double *clouds;
    const double *w; /* [B][C] */
} enc_ctx;

static double enc_objective(void *p)
{
    enc_ctx *c = p;
    double z[B * C], sum = 0.0;
    ref_encode(c->m, c->pd, c->clouds, B, N, z);
    for (int i = 0; i < B * C; i++) sum += c->w[i] * z[i];
    return sum;
}

static void test_encoder_grad(void **state)
{
    (void)state;
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 1, "test/atlas/encoder");
    tcb_atlas_model *m = make_model(12);
    tcb_atlas_encoder_cache cache;
    tcb_error err = {0};
    assert_int_equal(tcb_atlas_encoder_cache_alloc(&cache, B, N, C, &err), TCB_OK);
    float clouds[B * N * 3], w[B * C];
    tu_fill_uniform(&rng, clouds, B * N * 3, -0.5, 0.5);
    tu_fill_uniform(&rng, w, B * C, -1, 1);
    enc_ctx c = {m, tu_to_double(m->params, m->nparams), tu_to_double(clouds, B * N * 3),
                 tu_to_double(w, B * C)};
    tcb_atlas_encoder_forward(&m->enc, &cache, clouds);
    double zref[B * C];
    ref_encode(m, c.pd, c.clouds, B, N, zref);
    check_forward("encoder z", cache.z, zref, B * C);
    tcb_atlas_encoder_backward(&m->enc, &m->genc, &cache, w);
    for (int k = 0; k < TCB_ATLAS_ENC_LAYERS; k++) {
        const tcb_linear *l = &m->enc.l[k], *g = &m->genc.l[k];
        char what[64];
        snprintf(what, sizeof what, "encoder layer %d weight", k);
        check_grad(what, enc_objective, &c, c.pd + (l->W - m->params), g->W,
                   (size_t)l->in * l->out, 12, &rng);
        snprintf(what, sizeof what, "encoder layer %d bias", k);
        check_grad(what, enc_objective, &c, c.pd + (l->b - m->params), g->b, l->out, 8, &rng);
    }
    free(c.pd), free((void *)c.clouds), free((void *)c.w);
    tcb_atlas_encoder_cache_free(&cache);
    tcb_atlas_model_free(m);
}

/* -------------------------------------------------------------- model */

typedef struct {
    const tcb_atlas_model *m;
    double *pd;
    const double *clouds, *uv;
    const double *coef[3]; /* [B][M][3] each: a, b, c */
} model_ctx;

static double model_objective(void *p)
{
    model_ctx *c = p;
    double z[B * C], sum = 0.0;
    ref_encode(c->m, c->pd, c->clouds, B, N, z);
    for (int b = 0; b < B; b++)
        for (int i = 0; i < M; i++) {
            double out[3][3];
            ref_decode(c->m, c->pd, i / MP, z + b * C, c->uv[2 * i], c->uv[2 * i + 1], out);
            for (int k = 0; k < 3; k++)
                for (int j = 0; j < 3; j++)
                    sum += c->coef[k][((size_t)b * M + i) * 3 + j] * out[k][j];
        }
    return sum;
}

static void test_model_grad(void **state)
{
    (void)state;
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 1, "test/atlas/model");
    tcb_atlas_model *m = make_model(13);
    tcb_atlas_work *w;
    tcb_error err = {0};
    assert_int_equal(tcb_atlas_work_create(m, B, N, M, &w, &err), TCB_OK);
    float clouds[B * N * 3], uv[M * 2], out[3][B * M * 3], coef[3][B * M * 3];
    tu_fill_uniform(&rng, clouds, B * N * 3, -0.5, 0.5);
    tu_fill_uniform(&rng, uv, M * 2, 0, 1);
    for (int k = 0; k < 3; k++) tu_fill_uniform(&rng, coef[k], B * M * 3, -1, 1);
    tcb_atlas_model_forward(m, w, clouds, uv, out[0], out[1], out[2]);

    model_ctx c = {m, tu_to_double(m->params, m->nparams), tu_to_double(clouds, B * N * 3),
                   tu_to_double(uv, M * 2),
                   {tu_to_double(coef[0], B * M * 3), tu_to_double(coef[1], B * M * 3),
                    tu_to_double(coef[2], B * M * 3)}};
    double z[B * C], ref[3][B * M * 3];
    ref_encode(m, c.pd, c.clouds, B, N, z);
    for (int b = 0; b < B; b++)
        for (int i = 0; i < M; i++) {
            double o[3][3];
            ref_decode(m, c.pd, i / MP, z + b * C, c.uv[2 * i], c.uv[2 * i + 1], o);
            for (int k = 0; k < 3; k++)
                for (int j = 0; j < 3; j++) ref[k][(b * M + i) * 3 + j] = o[k][j];
        }
    check_forward("model phi", out[0], ref[0], B * M * 3);
    check_forward("model phi_u", out[1], ref[1], B * M * 3);
    check_forward("model phi_v", out[2], ref[2], B * M * 3);

    tcb_atlas_model_zero_grad(m);
    assert_int_equal(tcb_atlas_model_backward(m, w, coef[0], coef[1], coef[2], &err), TCB_OK);
    int nlayers = TCB_ATLAS_ENC_LAYERS + P * TCB_ATLAS_DEC_LAYERS;
    for (int k = 0; k < nlayers; k++) {
        const tcb_linear *l =
            k < TCB_ATLAS_ENC_LAYERS ? &m->enc.l[k]
                                     : &m->dec[(k - TCB_ATLAS_ENC_LAYERS) / TCB_ATLAS_DEC_LAYERS]
                                            .l[(k - TCB_ATLAS_ENC_LAYERS) % TCB_ATLAS_DEC_LAYERS];
        size_t ow = (size_t)(l->W - m->params), ob = (size_t)(l->b - m->params);
        char what[64];
        snprintf(what, sizeof what, "model layer %d weight", k);
        check_grad(what, model_objective, &c, c.pd + ow, m->grads + ow, (size_t)l->in * l->out,
                   8, &rng);
        snprintf(what, sizeof what, "model layer %d bias", k);
        check_grad(what, model_objective, &c, c.pd + ob, m->grads + ob, l->out, 6, &rng);
    }
    free(c.pd), free((void *)c.clouds), free((void *)c.uv);
    for (int k = 0; k < 3; k++) free((void *)c.coef[k]);
    tcb_atlas_work_free(w);
    tcb_atlas_model_free(m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_linear),          cmocka_unit_test(test_linear_threads), cmocka_unit_test(test_relu), cmocka_unit_test(test_leaky_relu),
        cmocka_unit_test(test_softplus),        cmocka_unit_test(test_maxpool),
        cmocka_unit_test(test_decoder_tangents), cmocka_unit_test(test_decoder_grad),
        cmocka_unit_test(test_encoder_grad),    cmocka_unit_test(test_model_grad),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
