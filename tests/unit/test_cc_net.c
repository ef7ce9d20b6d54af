/* Checks of the CC network (methods/cycle/{net,encoder,deform}.c) against a
 * naive double-precision reference written here: plain loops over rows, one
 * shape at a time for the predicted layers, no GEMM, the meta-MLP's slices of
 * θ located from net.h's documented layout (not from the code's views).
 *
 * Method as in test_atlas_grad.c: every float forward is compared with the
 * reference (|f − d| ≤ 1e-5·max|d|); every gradient with central
 * differences of the reference objective L = Σ a·out (random a) in double,
 * step h = 1e-6·max(1, |θ|), and passes iff
 *     |g − fd| ≤ 1e-3·|fd| + 1e-5·max_T |g|
 * with max_T over the tensor. All entries of small tensors are checked, the
 * first, the last and random ones of big ones.
 *
 * Kinks. The batch-norm outputs are O(1), so a ReLU input or a max-pool gap
 * may sit within an FD step of its kink. The reference hashes its activation
 * pattern (every ReLU's sign, every max-pool winner); an entry whose θ ± h
 * evaluations change the pattern is a difference across a kink and is skipped
 * (counted and reported; at most one in ten per tensor). The base point's
 * smallest |ReLU input| and max-pool gap must exceed 1e-6, so float and
 * double agree on the pattern there.
 *
 * Biases before a training-mode batch norm (every conv and Linear bias but
 * those of the parameter predictor's fc3 and of the last meta layer) have an
 * exactly zero gradient, the batch mean cancels them; so has the encoders'
 * bn3 β (the same shift of every cloud's pooled feature, which bnf cancels).
 * Those are checked to be zero, to float rounding, and their differences
 * too. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "methods/cycle/deform.h"
#include "methods/cycle/encoder.h"
#include "methods/cycle/net.h"
#include "tcb/json.h"
#include "testutil.h"

#define FD_H 1e-6
#define REL_TOL 1e-3
#define ABS_TOL 1e-5
#define FWD_TOL 1e-5
#define ZERO_TOL 1e-5 /* a zero gradient: |g| ≤ ZERO_TOL·(the largest gradient of the part) */

/* Tiny sizes reaching every code path: meta layer 0 has din 3 (the fused
 * tiny-input conv), layer 1 din = dout = H (GEMM), layer 2 dout 3 (the
 * fused tiny-output conv, tanh, no bn1); the predictor's fc2 6→3 and fc3
 * 3→K take the fused paths, fc1 12→6 the GEMM. */
enum { C = 8, Z = 6, H = 5, L = 2, B = 3, N = 7, R = B * N };
static const tcb_cc_dims DIMS = {C, Z, H, L, 0};

/* ---------------------------------------------------------------- helpers */

/* nb clouds of np points, each its own: a random centre in [−0.5, 0.5]³ and
 * a random size in [0.5, 1.5] around points uniform in [−1, 1]³. */
static void fill_clouds(tcb_rng *r, float *x, int nb, int np)
{
    for (int b = 0; b < nb; b++) {
        double c[3], s = 0.5 + tcb_rng_uniform(r);
        for (int k = 0; k < 3; k++) c[k] = tcb_rng_uniform(r) - 0.5;
        for (int i = 0; i < np; i++)
            for (int k = 0; k < 3; k++) x[((size_t)b * np + i) * 3 + k] = (float)(c[k] + s * (2.0 * tcb_rng_uniform(r) - 1.0));
    }
}

static double g_worst_fwd, g_worst_grad, g_worst_rel; /* the worst seen, reported at the end */
static int g_skipped, g_checked;

static void check_forward(const char *what, const float *got, const double *want, size_t n)
{
    double scale = 0.0, worst = 0.0;
    for (size_t i = 0; i < n; i++) scale = fmax(scale, fabs(want[i]));
    assert_true(scale > 0.0);
    for (size_t i = 0; i < n; i++) {
        double e = fabs(got[i] - want[i]);
        worst = fmax(worst, e / scale);
        if (!(e <= FWD_TOL * scale))
            fail_msg("%s[%zu] = %.9g, reference %.9g (scale %.3g)", what, i, got[i], want[i], scale);
    }
    g_worst_fwd = fmax(g_worst_fwd, worst);
    print_message("  %-44s max |f - d| / max|d| = %.2e\n", what, worst);
}

/* ------------------------------------------------ the double reference */

#define FNV_BASIS 14695981039346656037ull
#define FNV_PRIME 1099511628211ull

/* The reference network: double copies of the parameters and running
 * statistics, laid out as the float ones (the views give the offsets). */
typedef struct {
    const tcb_cc_net *net;
    double *pd; /* parameters (perturbed by the differences) */
    double *bd; /* running statistics, read in eval mode */
    double *nb; /* NULL, or where training forwards write the moved statistics */
    uint64_t sig;  /* activation pattern */
    double margin; /* smallest |ReLU input| or max-pool gap */
    double abs_tol; /* the gradient checks' floor, × max |g| of the tensor (ABS_TOL) */
} ref;

static void ref_open(ref *r, const tcb_cc_net *net)
{
    r->net = net;
    r->abs_tol = ABS_TOL;
    r->pd = tu_to_double(net->params, net->nparams);
    r->bd = tu_to_double(net->buffers, net->nbuffers);
    r->nb = NULL;
}

static void ref_close(ref *r)
{
    free(r->pd), free(r->bd), free(r->nb);
}

static void ref_begin(ref *r)
{
    r->sig = FNV_BASIS;
    r->margin = INFINITY;
}

static void note(ref *r, uint64_t v, double m)
{
    r->sig = (r->sig ^ v) * FNV_PRIME;
    r->margin = fmin(r->margin, m);
}

/* y [n][out] = x [n][in]·Wᵀ + b */
static void ref_linear(const ref *r, const tcb_linear *l, double *y, const double *x, int n)
{
    const double *W = r->pd + (l->W - r->net->params), *b = r->pd + (l->b - r->net->params);
    const int in = l->in, out = l->out;
    for (int i = 0; i < n; i++) {
        const double *xr = x + (size_t)i * in;
        for (int o = 0; o < out; o++) {
            const double *wr = W + (size_t)o * in;
            double s = b[o];
            for (int k = 0; k < in; k++) s += wr[k] * xr[k];
            y[(size_t)i * out + o] = s;
        }
    }
}

/* Batch norm over n rows, in place: training (batch mean, biased variance;
 * the moved running statistics into r->nb when set) or eval. */
static void ref_bn(ref *r, const tcb_batchnorm *bn, double *x, int n, int train)
{
    int Cn = bn->C;
    const double *g = r->pd + (bn->gamma - r->net->params), *be = r->pd + (bn->beta - r->net->params);
    size_t bo = (size_t)(bn->mean - r->net->buffers);
    const double *rm = r->bd + bo, *rv = rm + Cn;
    for (int c = 0; c < Cn; c++) {
        double m, v;
        if (train) {
            m = 0.0, v = 0.0;
            for (int i = 0; i < n; i++) m += x[(size_t)i * Cn + c];
            m /= n;
            for (int i = 0; i < n; i++) v += (x[(size_t)i * Cn + c] - m) * (x[(size_t)i * Cn + c] - m);
            v /= n;
            if (r->nb) {
                r->nb[bo + c] = 0.9 * rm[c] + 0.1 * m;
                r->nb[bo + Cn + c] = 0.9 * rv[c] + 0.1 * v * n / (n - 1.0);
            }
        } else
            m = rm[c], v = rv[c];
        for (int i = 0; i < n; i++) {
            double *p = &x[(size_t)i * Cn + c];
            *p = g[c] * (*p - m) / sqrt(v + 1e-5) + be[c];
        }
    }
}

static void ref_relu(ref *r, double *x, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        note(r, x[i] > 0.0, fabs(x[i]));
        x[i] = x[i] > 0.0 ? x[i] : 0.0;
    }
}

/* z [nb][Z] of clouds [nb][np][3] through encoder e. */
static void ref_encoder(ref *r, int e, const double *clouds, int nb, int np, int train, double *z)
{
    const tcb_cc_encoder *E = &r->net->p.enc[e];
    int rows = nb * np;
    double *h1 = tu_dalloc((size_t)rows * 64), *h2 = tu_dalloc((size_t)rows * 128), *h3 = tu_dalloc((size_t)rows * C);
    double g[64 * C];
    assert_true(nb <= 64);
    ref_linear(r, &E->conv1, h1, clouds, rows);
    ref_bn(r, &E->bn1, h1, rows, train);
    ref_relu(r, h1, (size_t)rows * 64);
    ref_linear(r, &E->conv2, h2, h1, rows);
    ref_bn(r, &E->bn2, h2, rows, train);
    ref_relu(r, h2, (size_t)rows * 128);
    ref_linear(r, &E->conv3, h3, h2, rows);
    ref_bn(r, &E->bn3, h3, rows, train);
    for (int b = 0; b < nb; b++) /* max over the cloud's points, noting the winner and its lead */
        for (int j = 0; j < C; j++) {
            int arg = 0;
            double best = -INFINITY, second = -INFINITY;
            for (int i = 0; i < np; i++) {
                double v = h3[((size_t)b * np + i) * C + j];
                if (v > best) second = best, best = v, arg = i;
                else if (v > second) second = v;
            }
            note(r, (uint64_t)arg, best - second);
            g[b * C + j] = best;
        }
    ref_linear(r, &E->fc, z, g, nb);
    ref_bn(r, &E->bnf, z, nb, train);
    ref_relu(r, z, (size_t)nb * Z);
    free(h1), free(h2), free(h3);
}

/* out [nb][np][3] deforming x [nb][np][3] given codes zx, zy [nb][Z]. The
 * meta layers' slices of θ follow net.h: per layer W [din][din] then b
 * [din], layer after layer. */
static void ref_deform(ref *r, const double *zx, const double *zy, const double *x, int nb, int np, int train,
                       double *out)
{
    const tcb_cc_net *net = r->net;
    const tcb_cc_predictor *P = &net->p.pred;
    const size_t K = 12 + (size_t)L * (H * H + H);
    int rows = nb * np;
    double lat[64 * 2 * Z], q1[64 * Z], q2[64 * Z / 2];
    assert_true(nb <= 64);
    double *th = tu_dalloc((size_t)nb * K), *h = tu_dalloc((size_t)rows * H), *v = tu_dalloc((size_t)rows * H);
    double *o = tu_dalloc((size_t)rows * H);
    for (int b = 0; b < nb; b++)
        for (int j = 0; j < Z; j++) lat[b * 2 * Z + j] = zx[b * Z + j], lat[b * 2 * Z + Z + j] = zy[b * Z + j];
    ref_linear(r, &P->fc1, q1, lat, nb);
    ref_bn(r, &P->bn1, q1, nb, train);
    ref_relu(r, q1, (size_t)nb * Z);
    ref_linear(r, &P->fc2, q2, q1, nb);
    ref_bn(r, &P->bn2, q2, nb, train);
    ref_relu(r, q2, (size_t)nb * (Z / 2));
    ref_linear(r, &P->fc3, th, q2, nb);
    memcpy(h, x, (size_t)rows * 3 * sizeof(double));
    size_t at = 0;
    for (int l = 0; l <= L; l++) {
        const tcb_cc_meta_layer *m = &net->p.meta[l];
        int din = l == 0 ? 3 : H, dout = l == L ? 3 : H;
        size_t w_at = at, b_at = at + (size_t)din * din;
        at = b_at + din;
        for (int b = 0; b < nb; b++) { /* v = (h + b_b)·(W_b + I), one shape at a time */
            const double *W = th + (size_t)b * K + w_at, *bias = th + (size_t)b * K + b_at;
            for (int i = 0; i < np; i++) {
                const double *hr = h + ((size_t)b * np + i) * din;
                double u[H > 3 ? H : 3];
                for (int k = 0; k < din; k++) u[k] = hr[k] + bias[k];
                for (int j = 0; j < din; j++) {
                    double s = 0.0;
                    for (int k = 0; k < din; k++) s += u[k] * (W[k * din + j] + (k == j));
                    v[((size_t)b * np + i) * din + j] = s;
                }
            }
        }
        ref_bn(r, &m->bn0, v, rows, train);
        ref_relu(r, v, (size_t)rows * din);
        ref_linear(r, &m->conv, o, v, rows);
        if (l < L) {
            ref_bn(r, &m->bn1, o, rows, train);
            ref_relu(r, o, (size_t)rows * dout);
        } else
            for (size_t k = 0; k < (size_t)rows * dout; k++) o[k] = tanh(o[k]);
        memcpy(h, o, (size_t)rows * dout * sizeof(double));
    }
    assert_true(at == K);
    for (size_t k = 0; k < (size_t)rows * 3; k++) out[k] = 2.0 * h[k];
    free(th), free(h), free(v), free(o);
}

/* ------------------------------------------------------- gradient checks */

typedef double (*objective_fn)(void *ctx); /* ctx starts with a ref */

/* grad[0..n) is the analytic gradient of f w.r.t. theta[0..n); checks
 * `count` entries (all when n ≤ count, else the first, the last and random
 * ones). zero: the gradient must vanish (a bias before a batch norm), to
 * ZERO_TOL·scale. */
static void check_grad(const char *what, objective_fn f, void *ctx, double *theta, const float *grad, size_t n,
                       int count, int zero, double scale, tcb_rng *rng)
{
    ref *r = ctx;
    double gmax = 0.0, worst = 0.0, worst_rel = 0.0;
    for (size_t i = 0; i < n; i++) gmax = fmax(gmax, fabs(grad[i]));
    if (zero) {
        if (!(gmax <= ZERO_TOL * scale)) fail_msg("%s: max |g| %.3g, should vanish (scale %.3g)", what, gmax, scale);
    } else
        assert_true(gmax > 0.0); /* an all-zero gradient would check nothing */
    ref_begin(r);
    f(ctx);
    uint64_t sig0 = r->sig;
    int k = n <= (size_t)count ? (int)n : count, skipped = 0;
    for (int s = 0; s < k; s++) {
        size_t i = n <= (size_t)count ? (size_t)s : s == 0 ? 0 : s == 1 ? n - 1 : tcb_rng_below(rng, (uint32_t)n);
        double t0 = theta[i], h = FD_H * fmax(1.0, fabs(t0));
        theta[i] = t0 + h;
        ref_begin(r);
        double fp = f(ctx);
        uint64_t sp = r->sig;
        theta[i] = t0 - h;
        ref_begin(r);
        double fm = f(ctx);
        uint64_t sm = r->sig;
        theta[i] = t0;
        if (sp != sig0 || sm != sig0) { /* the step crosses a kink */
            skipped++;
            continue;
        }
        double fd = (fp - fm) / (2.0 * h);
        if (zero) {
            if (!(fabs(fd) <= ZERO_TOL * scale))
                fail_msg("%s[%zu]: finite difference %.9g, should vanish (scale %.3g)", what, i, fd, scale);
            continue;
        }
        double e = fabs(grad[i] - fd), tol = REL_TOL * fabs(fd) + r->abs_tol * gmax;
        worst = fmax(worst, e / tol);
        if (fabs(fd) > 1e-2 * gmax) worst_rel = fmax(worst_rel, e / fabs(fd));
        if (!(e <= tol))
            fail_msg("%s[%zu]: analytic %.9g, finite difference %.9g (max |g| %.3g)", what, i, grad[i], fd, gmax);
    }
    if (skipped > (k + 9) / 10) fail_msg("%s: %d of %d differences cross a kink", what, skipped, k);
    g_skipped += skipped, g_checked += k - skipped;
    g_worst_grad = fmax(g_worst_grad, worst), g_worst_rel = fmax(g_worst_rel, worst_rel);
    if (zero)
        print_message("  %-44s %3d/%-5zu zero: max |g| %.1e (scale %.1e)%s\n", what, k - skipped, n, gmax, scale,
                      skipped ? " [kink skipped]" : "");
    else
        print_message("  %-44s %3d/%-5zu rel %.1e, %.3f of tol%s\n", what, k - skipped, n, worst_rel, worst,
                      skipped ? " [kink skipped]" : "");
}

/* The trained tensors, named as the CC code's state_dict; `zero` marks
 * biases before a training-mode batch norm. */
typedef struct {
    char name[96];
    const float *p; /* inside net->params */
    size_t n;
    int zero;
    int bn; /* 1: a batch norm's γ, 2: its β */
} tensor;

static int add_lin(tensor *t, int k, const char *pre, const tcb_linear *l, int zero_bias)
{
    snprintf(t[k].name, sizeof t[k].name, "%s.weight", pre);
    t[k].p = l->W, t[k].n = (size_t)l->in * l->out, t[k].zero = 0, t[k].bn = 0;
    k++;
    snprintf(t[k].name, sizeof t[k].name, "%s.bias", pre);
    t[k].p = l->b, t[k].n = (size_t)l->out, t[k].zero = zero_bias, t[k].bn = 0;
    return k + 1;
}

static int add_bn(tensor *t, int k, const char *pre, const tcb_batchnorm *bn)
{
    snprintf(t[k].name, sizeof t[k].name, "%s.weight", pre);
    t[k].p = bn->gamma, t[k].n = (size_t)bn->C, t[k].zero = 0, t[k].bn = 1;
    k++;
    snprintf(t[k].name, sizeof t[k].name, "%s.bias", pre);
    t[k].p = bn->beta, t[k].n = (size_t)bn->C, t[k].zero = 0, t[k].bn = 2;
    return k + 1;
}

static int enc_tensors(const tcb_cc_net *net, int e, tensor *t, int k)
{
    const tcb_cc_encoder *E = &net->p.enc[e];
    const char *pre = e ? "encoder2" : "encoder";
    char name[64];
    snprintf(name, sizeof name, "%s.0.conv1", pre), k = add_lin(t, k, name, &E->conv1, 1);
    snprintf(name, sizeof name, "%s.0.bn1", pre), k = add_bn(t, k, name, &E->bn1);
    snprintf(name, sizeof name, "%s.0.conv2", pre), k = add_lin(t, k, name, &E->conv2, 1);
    snprintf(name, sizeof name, "%s.0.bn2", pre), k = add_bn(t, k, name, &E->bn2);
    snprintf(name, sizeof name, "%s.0.conv3", pre), k = add_lin(t, k, name, &E->conv3, 1);
    snprintf(name, sizeof name, "%s.0.bn3", pre), k = add_bn(t, k, name, &E->bn3);
    t[k - 1].zero = 1; /* β3 shifts every cloud's pooled feature alike: fc passes the shift to every
                          shape alike, and bnf's batch mean cancels it */
    snprintf(name, sizeof name, "%s.1", pre), k = add_lin(t, k, name, &E->fc, 1);
    snprintf(name, sizeof name, "%s.2", pre), k = add_bn(t, k, name, &E->bnf);
    return k;
}

static int dec_tensors(const tcb_cc_net *net, tensor *t, int k)
{
    const tcb_cc_predictor *P = &net->p.pred;
    k = add_lin(t, k, "decoder.parameter_predictor.fc1", &P->fc1, 1);
    k = add_bn(t, k, "decoder.parameter_predictor.bn1", &P->bn1);
    k = add_lin(t, k, "decoder.parameter_predictor.fc2", &P->fc2, 1);
    k = add_bn(t, k, "decoder.parameter_predictor.bn2", &P->bn2);
    k = add_lin(t, k, "decoder.parameter_predictor.fc3", &P->fc3, 0);
    for (int l = 0; l <= net->d.L; l++) {
        const tcb_cc_meta_layer *m = &net->p.meta[l];
        char layer[16], name[64];
        if (l < net->d.L) snprintf(layer, sizeof layer, "fc_%d", l);
        else snprintf(layer, sizeof layer, "fc_end");
        snprintf(name, sizeof name, "decoder.MLP.%s.bn0", layer), k = add_bn(t, k, name, &m->bn0);
        snprintf(name, sizeof name, "decoder.MLP.%s.fc.conv1", layer), k = add_lin(t, k, name, &m->conv, l < net->d.L);
        if (l < net->d.L) snprintf(name, sizeof name, "decoder.MLP.%s.fc.bn1", layer), k = add_bn(t, k, name, &m->bn1);
    }
    return k;
}

#define MAX_TENSORS (2 * 16 + 10 + 6 * TCB_CC_MAX_META)

/* Every tensor of the list against differences of f in r->pd. */
static void check_tensors(const tensor *t, int nt, objective_fn f, void *ctx, int count, tcb_rng *rng)
{
    ref *r = ctx;
    const tcb_cc_net *net = r->net;
    double scale = 0.0;
    for (int k = 0; k < nt; k++)
        for (size_t i = 0; i < t[k].n; i++) scale = fmax(scale, fabs(net->grads[(t[k].p - net->params) + i]));
    for (int k = 0; k < nt; k++) {
        size_t off = (size_t)(t[k].p - net->params);
        check_grad(t[k].name, f, ctx, r->pd + off, net->grads + off, t[k].n, count, t[k].zero, scale, rng);
    }
}

/* ------------------------------------------------------------- fixtures */

/* A network at DIMS with the CC initialisation, then: conv weights redrawn
 * U(±1/√fan_in) (PyTorch's default, as the Linear ones: with N(0, 0.02)
 * weights under U(±1/√3) biases, conv1's outputs have |μ|/σ ≈ 100 over the
 * batch, and float rounding in them, amplified 100× by bn1, blurs the
 * comparison), batch-norm γ, β drawn in [0.5, 1.5] and [−0.5, 0.5] (so that
 * β = 0 hides nothing) and random running statistics (variances positive). */
static tcb_cc_net *make_net(uint64_t seed)
{
    tcb_cc_net *net;
    tcb_error err = {0};
    assert_int_equal(tcb_cc_net_create(&DIMS, &net, &err), TCB_OK);
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, seed, "test/cc/init");
    tcb_cc_net_init(net, &rng);
    tcb_linear *convs[3 * 2 + TCB_CC_MAX_META];
    int nc = 0;
    for (int e = 0; e < 2; e++)
        convs[nc++] = &net->p.enc[e].conv1, convs[nc++] = &net->p.enc[e].conv2, convs[nc++] = &net->p.enc[e].conv3;
    for (int l = 0; l <= L; l++) convs[nc++] = &net->p.meta[l].conv;
    for (int k = 0; k < nc; k++) {
        double bound = 1.0 / sqrt((double)convs[k]->in);
        tu_fill_uniform(&rng, convs[k]->W, (size_t)convs[k]->in * convs[k]->out, -bound, bound);
    }
    tensor t[MAX_TENSORS];
    int nt = dec_tensors(net, t, enc_tensors(net, 1, t, enc_tensors(net, 0, t, 0)));
    for (int k = 0; k < nt; k++)
        if (t[k].bn) tu_fill_uniform(&rng, net->params + (t[k].p - net->params), t[k].n, t[k].bn == 1 ? 0.5 : -0.5,
                                  t[k].bn == 1 ? 1.5 : 0.5);
    /* running means in [−0.5, 0.5], then the variances redrawn in [0.5, 2] */
    for (size_t i = 0; i < net->nbuffers; i++) net->buffers[i] = (float)(tcb_rng_uniform(&rng) - 0.5);
    tcb_cc_views *v = &net->p;
    const tcb_batchnorm *bns[64];
    int nb = 0;
    for (int e = 0; e < 2; e++)
        bns[nb++] = &v->enc[e].bn1, bns[nb++] = &v->enc[e].bn2, bns[nb++] = &v->enc[e].bn3, bns[nb++] = &v->enc[e].bnf;
    bns[nb++] = &v->pred.bn1, bns[nb++] = &v->pred.bn2;
    for (int l = 0; l <= L; l++) {
        bns[nb++] = &v->meta[l].bn0;
        if (l < L) bns[nb++] = &v->meta[l].bn1;
    }
    for (int k = 0; k < nb; k++) tu_fill_uniform(&rng, bns[k]->var, bns[k]->C, 0.5, 2.0);
    return net;
}

/* ------------------------------------------------------------ counts */

/* AE_Meta_AtlasNet at the CC code's sizes (C 1024, Z 512, H 64, L 6), its
 * used parameters (fc_end's FC_Layer builds a bn1 it never applies: its 6
 * are not counted; neither is PointNetfeat's STN, off):
 *   encoder (each of 2)
 *     conv1 3·64 + 64          =     256    bn1 2·64   =    128
 *     conv2 64·128 + 128       =   8,320    bn2 2·128  =    256
 *     conv3 128·1024 + 1024    = 132,096    bn3 2·1024 =  2,048
 *     Linear 1024·512 + 512    = 524,800    BN  2·512  =  1,024
 *     sum 668,928; two: 1,337,856
 *   parameter predictor (MetaVector 1024 → K)
 *     K = 9 + 3 + 6·(64·64 + 64) = 12 + 6·4,160 = 24,972
 *     fc1 1024·512 + 512       = 524,800    bn1 2·512  =  1,024
 *     fc2 512·256 + 256        = 131,328    bn2 2·256  =    512
 *     fc3 256·24,972 + 24,972  = 6,392,832 + 24,972 = 6,417,804
 *     sum 7,075,468
 *   meta-MLP (Meta_FC_Layer_2 fc_0 … fc_5, fc_end)
 *     fc_0    bn0 2·3 = 6,   conv 3·64 + 64  =   256, bn1 2·64 = 128:   390
 *     fc_1..5 bn0 2·64 = 128, conv 64·64 + 64 = 4,160, bn1 128:    5 · 4,416 = 22,080
 *     fc_end  bn0 128,        conv 64·3 + 3   =   195:                   323
 *     sum 22,793
 *   total 1,337,856 + 7,075,468 + 22,793 = 8,436,117
 * and the running statistics, 2 per batch-norm channel: widths 2·(64 + 128 +
 * 1024 + 512) + 512 + 256 + (3 + 6·64) + 6·64 = 4,995, so 9,990 floats. */
static void test_param_count(void **state)
{
    (void)state;
    const tcb_cc_dims paper = {1024, 512, 64, 6, 0};
    assert_int_equal(tcb_cc_param_count(&paper), 8436117);
    tcb_cc_net *net;
    tcb_error err = {0};
    assert_int_equal(tcb_cc_net_create(&paper, &net, &err), TCB_OK);
    assert_int_equal(net->K, 24972);
    assert_int_equal(net->nparams, 8436117);
    assert_int_equal(net->nbuffers, 9990);
    assert_int_equal(net->n_meta, 7);
    assert_int_equal(net->p.pred.fc3.out, 24972);
    tcb_cc_net_free(net);
    /* and the test's own sizes: K = 12 + 2·(25 + 5) = 72 */
    assert_int_equal(tcb_cc_param_count(&DIMS),
                     2 * ((3 * 64 + 64) + 2 * 64 + (64 * 128 + 128) + 2 * 128 + (128 * C + C) + 2 * C +
                          (C * Z + Z) + 2 * Z) +
                         (2 * Z * Z + Z + 2 * Z + Z * Z / 2 + Z / 2 + Z + Z / 2 * 72 + 72) +
                         (6 + 3 * H + H + 2 * H) + (2 * H + H * H + H + 2 * H) + (2 * H + 3 * H + 3));
    /* bad dims are refused, naming the one */
    const tcb_cc_dims odd = {C, 7, H, L, 0}, deep = {C, Z, H, TCB_CC_MAX_META, 0};
    assert_int_equal(tcb_cc_net_create(&odd, &net, &err), TCB_ERR_INPUT);
    assert_non_null(strstr(err.msg, "Z 7"));
    assert_int_equal(tcb_cc_net_create(&deep, &net, &err), TCB_ERR_INPUT);
    assert_non_null(strstr(err.msg, "L 33"));
}

/* The views sit where net.h's documented order puts them, walked here with
 * an independent offset: encoder X, encoder Y, predictor, meta layers; each
 * Linear W then b, each batch norm γ then β (buffers: mean then var). */
typedef struct {
    const float *base, *bufs;
    size_t off, boff;
} walker;

static void walk_lin(walker *w, const tcb_linear *l, int in, int out)
{
    assert_int_equal(l->in, in), assert_int_equal(l->out, out);
    assert_ptr_equal(l->W, w->base + w->off);
    w->off += (size_t)in * out;
    assert_ptr_equal(l->b, w->base + w->off);
    w->off += out;
}

static void walk_bn(walker *w, const tcb_batchnorm *bn, int Cn)
{
    assert_int_equal(bn->C, Cn);
    assert_ptr_equal(bn->gamma, w->base + w->off);
    assert_ptr_equal(bn->beta, w->base + w->off + Cn);
    w->off += 2 * (size_t)Cn;
    if (w->bufs) {
        assert_ptr_equal(bn->mean, w->bufs + w->boff);
        assert_ptr_equal(bn->var, w->bufs + w->boff + Cn);
        w->boff += 2 * (size_t)Cn;
    } else
        assert_null(bn->mean), assert_null(bn->var);
}

static void walk_views(const tcb_cc_net *net, const tcb_cc_views *v, const float *base, const float *bufs)
{
    walker w = {base, bufs, 0, 0};
    for (int e = 0; e < 2; e++) {
        const tcb_cc_encoder *E = &v->enc[e];
        walk_lin(&w, &E->conv1, 3, 64), walk_bn(&w, &E->bn1, 64);
        walk_lin(&w, &E->conv2, 64, 128), walk_bn(&w, &E->bn2, 128);
        walk_lin(&w, &E->conv3, 128, C), walk_bn(&w, &E->bn3, C);
        walk_lin(&w, &E->fc, C, Z), walk_bn(&w, &E->bnf, Z);
    }
    size_t K = 12 + (size_t)L * (H * H + H), at = 0;
    walk_lin(&w, &v->pred.fc1, 2 * Z, Z), walk_bn(&w, &v->pred.bn1, Z);
    walk_lin(&w, &v->pred.fc2, Z, Z / 2), walk_bn(&w, &v->pred.bn2, Z / 2);
    walk_lin(&w, &v->pred.fc3, Z / 2, (int)K);
    for (int l = 0; l <= L; l++) {
        const tcb_cc_meta_layer *m = &v->meta[l];
        int din = l == 0 ? 3 : H, dout = l == L ? 3 : H;
        assert_int_equal(m->din, din), assert_int_equal(m->dout, dout);
        assert_int_equal(m->w_at, at), assert_int_equal(m->b_at, at + (size_t)din * din);
        at += (size_t)din * din + din;
        walk_bn(&w, &m->bn0, din);
        walk_lin(&w, &m->conv, din, dout);
        if (l < L) walk_bn(&w, &m->bn1, dout);
        else assert_int_equal(m->bn1.C, 0);
    }
    assert_int_equal(at, K), assert_int_equal(net->K, K);
    assert_int_equal(w.off, net->nparams);
    if (bufs) assert_int_equal(w.boff, net->nbuffers);
}

static void test_layout(void **state)
{
    (void)state;
    tcb_cc_net *net;
    tcb_error err = {0};
    assert_int_equal(tcb_cc_net_create(&DIMS, &net, &err), TCB_OK);
    assert_int_equal(net->n_meta, L + 1);
    walk_views(net, &net->p, net->params, net->buffers);
    walk_views(net, &net->g, net->grads, NULL);
    for (size_t i = 0; i < net->nparams; i++) assert_true(net->params[i] == 0.0f && net->grads[i] == 0.0f);
    tcb_cc_net_free(net);
}

/* ------------------------------------------------------------ init */

typedef struct {
    double n, s, ss, amax;
} moments;

static void acc(moments *m, const float *x, size_t n)
{
    for (size_t i = 0; i < n; i++) m->n++, m->s += x[i], m->ss += (double)x[i] * x[i], m->amax = fmax(m->amax, fabs(x[i]));
}

static double mean_of(const moments *m) { return m->s / m->n; }
static double std_of(const moments *m) { return sqrt(m->ss / m->n - mean_of(m) * mean_of(m)); }

/* A conv weight tensor: N(0, 0.02), its sample std within 10 % (tensors of
 * ≥ 1000 entries, and all of them pooled). */
static void check_conv(const tcb_linear *l, moments *pool)
{
    moments m = {0};
    size_t n = (size_t)l->in * l->out;
    acc(&m, l->W, n), acc(pool, l->W, n);
    if (n >= 1000) {
        if (!(fabs(std_of(&m) - 0.02) <= 0.002)) fail_msg("conv %d→%d: weight std %.5f", l->in, l->out, std_of(&m));
        assert_true(fabs(mean_of(&m)) <= 5 * 0.02 / sqrt((double)n));
    }
    double bound = 1.0 / sqrt((double)l->in);
    for (int i = 0; i < l->out; i++) assert_true(fabs(l->b[i]) <= bound);
}

/* A Linear (and a conv's bias): U(±1/√fan_in), spread to the bound. */
static void check_uniform(const float *x, size_t n, int fan_in)
{
    double bound = 1.0 / sqrt((double)fan_in);
    moments m = {0};
    acc(&m, x, n);
    for (size_t i = 0; i < n; i++)
        if (!(fabs(x[i]) <= bound)) fail_msg("entry %zu = %g outside ±%g", i, x[i], bound);
    if (n >= 1000) {
        assert_true(m.amax >= 0.99 * bound);
        assert_true(fabs(std_of(&m) - bound / sqrt(3.0)) <= 0.05 * bound / sqrt(3.0));
    }
}

static void test_init(void **state)
{
    (void)state;
    const tcb_cc_dims d = {256, 64, 32, 3, 0};
    tcb_cc_net *net, *again;
    tcb_error err = {0};
    assert_int_equal(tcb_cc_net_create(&d, &net, &err), TCB_OK);
    assert_int_equal(tcb_cc_net_create(&d, &again, &err), TCB_OK);
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 3, "test/cc/init");
    tcb_cc_net_init(net, &rng);
    tcb_rng_seed_stream(&rng, 3, "test/cc/init");
    tcb_cc_net_init(again, &rng);
    assert_memory_equal(net->params, again->params, net->nparams * sizeof(float)); /* seeded */

    const tcb_cc_views *v = &net->p;
    moments conv = {0}, gamma = {0};
    const tcb_batchnorm *bns[64];
    int nb = 0;
    for (int e = 0; e < 2; e++) {
        const tcb_cc_encoder *E = &v->enc[e];
        check_conv(&E->conv1, &conv), check_conv(&E->conv2, &conv), check_conv(&E->conv3, &conv);
        check_uniform(E->fc.W, (size_t)d.C * d.Z, d.C), check_uniform(E->fc.b, d.Z, d.C);
        bns[nb++] = &E->bn1, bns[nb++] = &E->bn2, bns[nb++] = &E->bn3, bns[nb++] = &E->bnf;
    }
    const tcb_cc_predictor *P = &v->pred;
    check_uniform(P->fc1.W, (size_t)2 * d.Z * d.Z, 2 * d.Z), check_uniform(P->fc1.b, d.Z, 2 * d.Z);
    check_uniform(P->fc2.W, (size_t)d.Z * d.Z / 2, d.Z), check_uniform(P->fc2.b, d.Z / 2, d.Z);
    check_uniform(P->fc3.W, (size_t)d.Z / 2 * net->K, d.Z / 2), check_uniform(P->fc3.b, net->K, d.Z / 2);
    bns[nb++] = &P->bn1, bns[nb++] = &P->bn2;
    for (int l = 0; l < net->n_meta; l++) {
        check_conv(&v->meta[l].conv, &conv);
        bns[nb++] = &v->meta[l].bn0;
        if (v->meta[l].bn1.C) bns[nb++] = &v->meta[l].bn1;
    }
    print_message("  conv weights: %.0f, mean %.2e, std %.5f\n", conv.n, mean_of(&conv), std_of(&conv));
    assert_true(fabs(std_of(&conv) - 0.02) <= 0.002);
    assert_true(fabs(mean_of(&conv)) <= 5 * 0.02 / sqrt(conv.n));
    for (int k = 0; k < nb; k++) {
        acc(&gamma, bns[k]->gamma, bns[k]->C);
        for (int c = 0; c < bns[k]->C; c++) {
            assert_true(bns[k]->beta[c] == 0.0f);
            assert_true(bns[k]->mean[c] == 0.0f && bns[k]->var[c] == 1.0f);
        }
    }
    print_message("  batch-norm gamma: %.0f, mean %.5f, std %.5f\n", gamma.n, mean_of(&gamma), std_of(&gamma));
    assert_true(fabs(mean_of(&gamma) - 1.0) <= 5 * 0.02 / sqrt(gamma.n));
    assert_true(fabs(std_of(&gamma) - 0.02) <= 0.002);
    tcb_cc_net_free(net), tcb_cc_net_free(again);
}

/* ------------------------------------------------------------ encoder */

typedef struct {
    ref r;
    int e;
    const double *clouds, *a; /* [B][N][3], [B][Z] */
} enc_ctx;

static double enc_objective(void *p)
{
    enc_ctx *c = p;
    double z[B * Z], sum = 0.0;
    ref_encoder(&c->r, c->e, c->clouds, B, N, 1, z);
    for (int i = 0; i < B * Z; i++) sum += c->a[i] * z[i];
    return sum;
}

typedef struct {
    tcb_cc_encoder_cache cache;
    float *scratch;
} enc_work;

static void enc_work_open(enc_work *w)
{
    tcb_error err = {0};
    assert_int_equal(tcb_cc_encoder_cache_alloc(&w->cache, &DIMS, B, N, &err), TCB_OK);
    w->scratch = tu_falloc(tcb_cc_encoder_scratch_floats(&DIMS, B, N));
}

static void enc_work_close(enc_work *w)
{
    tcb_cc_encoder_cache_free(&w->cache);
    free(w->scratch);
}

/* Training mode, each encoder: z, the moved running statistics, and every
 * parameter's gradient of Σ a·z. */
static void test_encoder_train(void **state)
{
    (void)state;
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 1, "test/cc/encoder");
    for (int e = 0; e < 2; e++) {
        print_message(" encoder %d\n", e);
        tcb_cc_net *net = make_net(20 + e);
        enc_work w;
        enc_work_open(&w);
        float clouds[B * N * 3], a[B * Z];
        tu_fill_uniform(&rng, clouds, B * N * 3, -1, 1);
        tu_fill_uniform(&rng, a, B * Z, -1, 1);
        enc_ctx c = {.e = e, .clouds = tu_to_double(clouds, B * N * 3), .a = tu_to_double(a, B * Z)};
        ref_open(&c.r, net);
        c.r.nb = tu_to_double(net->buffers, net->nbuffers);

        tcb_cc_encoder_forward(&net->p.enc[e], &w.cache, w.scratch, clouds, 1);
        double z[B * Z];
        ref_begin(&c.r);
        ref_encoder(&c.r, e, c.clouds, B, N, 1, z);
        print_message("  smallest |ReLU input| or max-pool gap %.2e\n", c.r.margin);
        assert_true(c.r.margin > 1e-6);
        check_forward("encoder z (train)", w.cache.z, z, B * Z);
        check_forward("running statistics after a training forward", net->buffers, c.r.nb, net->nbuffers);
        free(c.r.nb), c.r.nb = NULL;

        tcb_cc_net_zero_grad(net);
        tcb_cc_encoder_backward(&net->p.enc[e], &net->g.enc[e], &w.cache, w.scratch, a);
        tensor t[MAX_TENSORS];
        int nt = enc_tensors(net, e, t, 0);
        check_tensors(t, nt, enc_objective, &c, 24, &rng);
        /* the other encoder and the decoder got nothing */
        tensor rest[MAX_TENSORS];
        int nr = dec_tensors(net, rest, enc_tensors(net, 1 - e, rest, 0));
        for (int k = 0; k < nr; k++)
            for (size_t i = 0; i < rest[k].n; i++) assert_true(net->grads[(rest[k].p - net->params) + i] == 0.0f);

        ref_close(&c.r);
        free((void *)c.clouds), free((void *)c.a);
        enc_work_close(&w);
        tcb_cc_net_free(net);
    }
}

/* Eval mode with random running statistics: z, and nothing moves. */
static void test_encoder_eval(void **state)
{
    (void)state;
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 1, "test/cc/encoder-eval");
    tcb_cc_net *net = make_net(22);
    enc_work w;
    enc_work_open(&w);
    float clouds[B * N * 3];
    tu_fill_uniform(&rng, clouds, B * N * 3, -1, 1);
    float *b0 = tu_falloc(net->nbuffers);
    memcpy(b0, net->buffers, net->nbuffers * sizeof(float));
    ref r;
    ref_open(&r, net);
    double *xd = tu_to_double(clouds, B * N * 3), z[B * Z];
    for (int e = 0; e < 2; e++) {
        tcb_cc_encoder_forward(&net->p.enc[e], &w.cache, w.scratch, clouds, 0);
        ref_begin(&r);
        ref_encoder(&r, e, xd, B, N, 0, z);
        check_forward(e ? "encoder 1 z (eval)" : "encoder 0 z (eval)", w.cache.z, z, B * Z);
    }
    assert_memory_equal(net->buffers, b0, net->nbuffers * sizeof(float));
    ref_close(&r);
    free(xd), free(b0);
    enc_work_close(&w);
    tcb_cc_net_free(net);
}

/* count_again moves the running statistics exactly as a second training
 * forward of the same clouds does, and nothing else. */
static void test_count_again(void **state)
{
    (void)state;
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 1, "test/cc/count-again");
    tcb_cc_net *once = make_net(23), *twice = make_net(23);
    float *b0 = tu_falloc(once->nbuffers);
    memcpy(b0, once->buffers, once->nbuffers * sizeof(float));
    enc_work w1, w2;
    enc_work_open(&w1), enc_work_open(&w2);
    float clouds[B * N * 3], z1[B * Z];
    tu_fill_uniform(&rng, clouds, B * N * 3, -1, 1);
    for (int e = 0; e < 2; e++) {
        tcb_cc_encoder_forward(&once->p.enc[e], &w1.cache, w1.scratch, clouds, 1);
        tcb_cc_encoder_count_again(&once->p.enc[e], &w1.cache);
        tcb_cc_encoder_forward(&twice->p.enc[e], &w2.cache, w2.scratch, clouds, 1);
        memcpy(z1, w2.cache.z, sizeof z1);
        tcb_cc_encoder_forward(&twice->p.enc[e], &w2.cache, w2.scratch, clouds, 1);
        assert_memory_equal(z1, w2.cache.z, sizeof z1); /* the same output: batch statistics */
        assert_memory_equal(w1.cache.z, w2.cache.z, sizeof z1);
        assert_memory_equal(once->buffers, twice->buffers, once->nbuffers * sizeof(float));
    }
    /* every encoder statistic moved; the decoder's did not */
    const tcb_batchnorm *first = &once->p.pred.bn1;
    size_t enc_end = (size_t)(first->mean - once->buffers);
    size_t moved = 0;
    for (size_t i = 0; i < enc_end; i++) moved += once->buffers[i] != b0[i];
    assert_true(moved > enc_end * 9 / 10);
    assert_memory_equal(once->buffers + enc_end, b0 + enc_end, (once->nbuffers - enc_end) * sizeof(float));
    free(b0);
    enc_work_close(&w1), enc_work_close(&w2);
    tcb_cc_net_free(once), tcb_cc_net_free(twice);
}

/* ------------------------------------------------------------ decoder */

typedef struct {
    ref r;
    double *zx, *zy;
    const double *x, *a; /* [B][N][3] each */
} dec_ctx;

static double dec_objective(void *p)
{
    dec_ctx *c = p;
    double out[R * 3], sum = 0.0;
    ref_deform(&c->r, c->zx, c->zy, c->x, B, N, 1, out);
    for (int i = 0; i < R * 3; i++) sum += c->a[i] * out[i];
    return sum;
}

typedef struct {
    tcb_cc_deform_cache cache;
    float *scratch;
} dec_work;

static void dec_work_open(dec_work *w, const tcb_cc_net *net)
{
    tcb_error err = {0};
    assert_int_equal(tcb_cc_deform_cache_alloc(&w->cache, net, B, N, &err), TCB_OK);
    w->scratch = tu_falloc(tcb_cc_deform_scratch_floats(net, B, N));
}

static void dec_work_close(dec_work *w)
{
    tcb_cc_deform_cache_free(&w->cache);
    free(w->scratch);
}

static void test_decoder_train(void **state)
{
    (void)state;
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 1, "test/cc/decoder");
    tcb_cc_net *net = make_net(30);
    dec_work w;
    dec_work_open(&w, net);
    float zx[B * Z], zy[B * Z], x[R * 3], a[R * 3];
    tu_fill_uniform(&rng, zx, B * Z, 0, 2); /* latent codes come out of a ReLU */
    tu_fill_uniform(&rng, zy, B * Z, 0, 2);
    tu_fill_uniform(&rng, x, R * 3, -1, 1);
    tu_fill_uniform(&rng, a, R * 3, -1, 1);
    dec_ctx c = {.zx = tu_to_double(zx, B * Z), .zy = tu_to_double(zy, B * Z), .x = tu_to_double(x, R * 3),
                 .a = tu_to_double(a, R * 3)};
    ref_open(&c.r, net);
    c.r.nb = tu_to_double(net->buffers, net->nbuffers);

    tcb_cc_deform_forward(net, &w.cache, w.scratch, zx, zy, x, 1);
    double out[R * 3];
    ref_begin(&c.r);
    ref_deform(&c.r, c.zx, c.zy, c.x, B, N, 1, out);
    print_message("  smallest |ReLU input| %.2e\n", c.r.margin);
    assert_true(c.r.margin > 1e-6);
    check_forward("decoder out (train)", w.cache.out, out, R * 3);
    check_forward("running statistics after a training forward", net->buffers, c.r.nb, net->nbuffers);
    free(c.r.nb), c.r.nb = NULL;

    /* backward accumulates: into gradients and codes' gradients set to 0 */
    tcb_cc_net_zero_grad(net);
    float dzx[B * Z] = {0}, dzy[B * Z] = {0};
    tcb_cc_deform_backward(net, &w.cache, w.scratch, a, dzx, dzy);
    tensor t[MAX_TENSORS];
    int nt = dec_tensors(net, t, 0);
    check_tensors(t, nt, dec_objective, &c, 24, &rng);
    check_grad("d z_X", dec_objective, &c, c.zx, dzx, B * Z, B * Z, 0, 0.0, &rng);
    check_grad("d z_Y", dec_objective, &c, c.zy, dzy, B * Z, B * Z, 0, 0.0, &rng);
    tensor enc[MAX_TENSORS];
    int ne = enc_tensors(net, 1, enc, enc_tensors(net, 0, enc, 0));
    for (int k = 0; k < ne; k++)
        for (size_t i = 0; i < enc[k].n; i++) assert_true(net->grads[(enc[k].p - net->params) + i] == 0.0f);

    /* a second backward adds as much again */
    float *g1 = tu_falloc(net->nparams), dzx1[B * Z], dzy1[B * Z];
    memcpy(g1, net->grads, net->nparams * sizeof(float));
    memcpy(dzx1, dzx, sizeof dzx), memcpy(dzy1, dzy, sizeof dzy);
    tcb_cc_deform_backward(net, &w.cache, w.scratch, a, dzx, dzy);
    for (size_t i = 0; i < net->nparams; i++) assert_near(net->grads[i], 2.0f * g1[i], 1e-6 * fabs(g1[i]));
    for (int i = 0; i < B * Z; i++) {
        assert_near(dzx[i], 2.0f * dzx1[i], 1e-6 * fabs(dzx1[i]));
        assert_near(dzy[i], 2.0f * dzy1[i], 1e-6 * fabs(dzy1[i]));
    }

    free(g1);
    ref_close(&c.r);
    free(c.zx), free(c.zy), free((void *)c.x), free((void *)c.a);
    dec_work_close(&w);
    tcb_cc_net_free(net);
}

static void test_decoder_eval(void **state)
{
    (void)state;
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 1, "test/cc/decoder-eval");
    tcb_cc_net *net = make_net(31);
    dec_work w;
    dec_work_open(&w, net);
    float zx[B * Z], zy[B * Z], x[R * 3];
    tu_fill_uniform(&rng, zx, B * Z, 0, 2);
    tu_fill_uniform(&rng, zy, B * Z, 0, 2);
    tu_fill_uniform(&rng, x, R * 3, -1, 1);
    float *b0 = tu_falloc(net->nbuffers);
    memcpy(b0, net->buffers, net->nbuffers * sizeof(float));
    tcb_cc_deform_forward(net, &w.cache, w.scratch, zx, zy, x, 0);
    ref r;
    ref_open(&r, net);
    double *zxd = tu_to_double(zx, B * Z), *zyd = tu_to_double(zy, B * Z), *xd = tu_to_double(x, R * 3), out[R * 3];
    ref_begin(&r);
    ref_deform(&r, zxd, zyd, xd, B, N, 0, out);
    check_forward("decoder out (eval)", w.cache.out, out, R * 3);
    assert_memory_equal(net->buffers, b0, net->nbuffers * sizeof(float));
    ref_close(&r);
    free(zxd), free(zyd), free(xd), free(b0);
    dec_work_close(&w);
    tcb_cc_net_free(net);
}

/* residual: the same network emits x + its absolute output, in both
 * modes; the parameter gradients are the same (x is data). */
static void test_decoder_residual(void **state)
{
    (void)state;
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 1, "test/cc/decoder-residual");
    tcb_cc_net *plain = make_net(31), *res = make_net(31);
    res->d.residual = 1;
    dec_work wp, wr;
    dec_work_open(&wp, plain);
    dec_work_open(&wr, res);
    float zx[B * Z], zy[B * Z], x[R * 3], dout[R * 3];
    tu_fill_uniform(&rng, zx, B * Z, 0, 2);
    tu_fill_uniform(&rng, zy, B * Z, 0, 2);
    tu_fill_uniform(&rng, x, R * 3, -1, 1);
    tu_fill_uniform(&rng, dout, R * 3, -1, 1);
    for (int train = 0; train < 2; train++) {
        tcb_cc_deform_forward(plain, &wp.cache, wp.scratch, zx, zy, x, train);
        tcb_cc_deform_forward(res, &wr.cache, wr.scratch, zx, zy, x, train);
        for (int k = 0; k < R * 3; k++) assert_true(wr.cache.out[k] == wp.cache.out[k] + x[k]);
    }
    float dzx[2][B * Z] = {{0}}, dzy[2][B * Z] = {{0}};
    tcb_cc_net_zero_grad(plain), tcb_cc_net_zero_grad(res);
    tcb_cc_deform_backward(plain, &wp.cache, wp.scratch, dout, dzx[0], dzy[0]);
    tcb_cc_deform_backward(res, &wr.cache, wr.scratch, dout, dzx[1], dzy[1]);
    assert_memory_equal(plain->grads, res->grads, plain->nparams * sizeof(float));
    assert_memory_equal(dzx[0], dzx[1], sizeof dzx[0]);
    assert_memory_equal(dzy[0], dzy[1], sizeof dzy[0]);
    dec_work_close(&wp), dec_work_close(&wr);
    tcb_cc_net_free(plain), tcb_cc_net_free(res);
}

/* ------------------------------------------------- the whole network call */

typedef struct {
    ref r;
    const double *X, *Y, *a;
} net_ctx;

static double net_objective(void *p)
{
    net_ctx *c = p;
    double zx[B * Z], zy[B * Z], out[R * 3], sum = 0.0;
    ref_encoder(&c->r, 0, c->X, B, N, 1, zx);
    ref_encoder(&c->r, 1, c->Y, B, N, 1, zy);
    ref_deform(&c->r, zx, zy, c->X, B, N, 1, out);
    for (int i = 0; i < R * 3; i++) sum += c->a[i] * out[i];
    return sum;
}

/* out = deform(encoder0(X), encoder1(Y), X) in training mode, the
 * backwards chained through dz_X, dz_Y; every parameter against the
 * differences of the composed reference.
 *
 * The seed. At these tiny widths each batch norm amplifies the float
 * rounding of its input by Σ|terms|/σ ≈ 5–65, and the stages compound: over
 * network seeds 40–69 the float output strays from the double one by up to
 * ~1e-5 relative, and small gradient entries (~1 % of their tensor's max)
 * by up to ~3e-5·max|g|, where 1-ulp nudges of the clouds move the float
 * gradient by as much (float noise, not a wrong backward: a broken backward
 * misses by orders of magnitude). Seed 53 sits well inside the tolerances
 * (worst entry 0.06 of its tolerance, forward 2e-7); the gradient floor is
 * raised to 1e-4·max|g| all the same, since another CPU's OpenBLAS kernels
 * round differently and could land a seed's small entries on the 3e-5 seen
 * above. */
static void test_network_grad(void **state)
{
    (void)state;
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 1, "test/cc/network");
    tcb_cc_net *net = make_net(53);
    enc_work e0, e1;
    dec_work d;
    enc_work_open(&e0), enc_work_open(&e1), dec_work_open(&d, net);
    float X[R * 3], Y[R * 3], a[R * 3];
    fill_clouds(&rng, X, B, N);
    fill_clouds(&rng, Y, B, N);
    tu_fill_uniform(&rng, a, R * 3, -1, 1);
    net_ctx c = {.X = tu_to_double(X, R * 3), .Y = tu_to_double(Y, R * 3), .a = tu_to_double(a, R * 3)};
    ref_open(&c.r, net);
    c.r.abs_tol = 1e-4;

    tcb_cc_encoder_forward(&net->p.enc[0], &e0.cache, e0.scratch, X, 1);
    tcb_cc_encoder_forward(&net->p.enc[1], &e1.cache, e1.scratch, Y, 1);
    tcb_cc_deform_forward(net, &d.cache, d.scratch, e0.cache.z, e1.cache.z, X, 1);
    double zx[B * Z], zy[B * Z], out[R * 3];
    ref_begin(&c.r);
    ref_encoder(&c.r, 0, c.X, B, N, 1, zx);
    ref_encoder(&c.r, 1, c.Y, B, N, 1, zy);
    ref_deform(&c.r, zx, zy, c.X, B, N, 1, out);
    print_message("  smallest |ReLU input| or max-pool gap %.2e\n", c.r.margin);
    assert_true(c.r.margin > 1e-6);
    check_forward("z_X", e0.cache.z, zx, B * Z);
    check_forward("z_Y", e1.cache.z, zy, B * Z);
    /* the decoder alone at the float codes, then the whole composition (whose
     * float error is the codes' rounding, amplified by the decoder) */
    double *zxf = tu_to_double(e0.cache.z, B * Z), *zyf = tu_to_double(e1.cache.z, B * Z), stage[R * 3];
    ref_deform(&c.r, zxf, zyf, c.X, B, N, 1, stage);
    check_forward("out vs the reference decoder at the float codes", d.cache.out, stage, R * 3);
    check_forward("out vs the composed reference", d.cache.out, out, R * 3);
    free(zxf), free(zyf);

    tcb_cc_net_zero_grad(net);
    float dzx[B * Z] = {0}, dzy[B * Z] = {0};
    tcb_cc_deform_backward(net, &d.cache, d.scratch, a, dzx, dzy);
    tcb_cc_encoder_backward(&net->p.enc[0], &net->g.enc[0], &e0.cache, e0.scratch, dzx);
    tcb_cc_encoder_backward(&net->p.enc[1], &net->g.enc[1], &e1.cache, e1.scratch, dzy);
    tensor t[MAX_TENSORS];
    int nt = dec_tensors(net, t, enc_tensors(net, 1, t, enc_tensors(net, 0, t, 0)));
    size_t covered = 0;
    for (int k = 0; k < nt; k++) covered += t[k].n;
    assert_int_equal(covered, net->nparams); /* every parameter is in the list */
    check_tensors(t, nt, net_objective, &c, 12, &rng);

    ref_close(&c.r);
    free((void *)c.X), free((void *)c.Y), free((void *)c.a);
    enc_work_close(&e0), enc_work_close(&e1), dec_work_close(&d);
    tcb_cc_net_free(net);
    print_message(" all gradient checks so far: %d entries, %d skipped at kinks; worst %.3f of the tolerance, worst "
                  "relative error %.2e; worst forward %.2e\n",
                  g_checked, g_skipped, g_worst_grad, g_worst_rel, g_worst_fwd);
}

/* ------------------------------------------------------------ export */

static const cJSON *find_tensor(const cJSON *manifest, const char *name)
{
    const cJSON *t;
    cJSON_ArrayForEach(t, cJSON_GetObjectItemCaseSensitive(manifest, "tensors"))
    {
        const cJSON *n = cJSON_GetObjectItemCaseSensitive(t, "name");
        if (cJSON_IsString(n) && !strcmp(n->valuestring, name)) return t;
    }
    return NULL;
}

static double num(const cJSON *o, const char *key)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
    assert_true(cJSON_IsNumber(v));
    return v->valuedouble;
}

static void test_export_import(void **state)
{
    const char *dir = *state;
    tcb_cc_net *net = make_net(50), *back;
    tcb_error err = {0};
    char bin[4200], man[4200];
    snprintf(bin, sizeof bin, "%s/cc.bin", dir);
    snprintf(man, sizeof man, "%s/cc.json", dir);

    /* the manifest: contiguous tensors, parameters then buffers, at the views */
    cJSON *m = tcb_cc_net_manifest(net);
    assert_int_equal((int)num(m, "nparams"), net->nparams);
    assert_int_equal((int)num(m, "nbuffers"), net->nbuffers);
    size_t next = 0;
    const cJSON *it;
    cJSON_ArrayForEach(it, cJSON_GetObjectItemCaseSensitive(m, "tensors"))
    {
        assert_int_equal((size_t)num(it, "offset"), next);
        next += (size_t)num(it, "count");
    }
    assert_int_equal(next, net->nparams + net->nbuffers);
    tensor t[MAX_TENSORS];
    int nt = dec_tensors(net, t, enc_tensors(net, 1, t, enc_tensors(net, 0, t, 0)));
    for (int k = 0; k < nt; k++) {
        const cJSON *e = find_tensor(m, t[k].name);
        if (!e) fail_msg("no tensor %s in the manifest", t[k].name);
        assert_int_equal((size_t)num(e, "offset"), (size_t)(t[k].p - net->params));
        assert_int_equal((size_t)num(e, "count"), t[k].n);
    }
    const cJSON *w1 = find_tensor(m, "encoder.0.conv1.weight"), *rm = find_tensor(m, "decoder.MLP.fc_end.bn0.running_var");
    assert_non_null(w1), assert_non_null(rm);
    const cJSON *shape = cJSON_GetObjectItemCaseSensitive(w1, "shape");
    assert_int_equal(cJSON_GetArraySize(shape), 2);
    assert_int_equal(cJSON_GetArrayItem(shape, 0)->valueint, 64), assert_int_equal(cJSON_GetArrayItem(shape, 1)->valueint, 3);
    assert_int_equal((size_t)num(rm, "offset"), net->nparams + (size_t)(net->p.meta[L].bn0.var - net->buffers));
    assert_null(find_tensor(m, "decoder.MLP.fc_end.fc.bn1.weight")); /* built by the CC code, never used */
    cJSON_Delete(m);

    /* round trip, bit for bit */
    assert_int_equal(tcb_cc_net_export(net, bin, man, &err), TCB_OK);
    assert_int_equal(tcb_cc_net_create(&DIMS, &back, &err), TCB_OK);
    assert_int_equal(tcb_cc_net_import(back, bin, man, &err), TCB_OK);
    assert_memory_equal(back->params, net->params, net->nparams * sizeof(float));
    assert_memory_equal(back->buffers, net->buffers, net->nbuffers * sizeof(float));
    tcb_cc_net_free(back);

    /* other dims: refused, naming the file and the key */
    const tcb_cc_dims other_h = {C, Z, H + 1, L, 0}, other_c = {2 * C, Z, H, L, 0};
    const char *key[2] = {".H:", ".C:"};
    for (int k = 0; k < 2; k++) {
        assert_int_equal(tcb_cc_net_create(k ? &other_c : &other_h, &back, &err), TCB_OK);
        tcb_error_clear(&err);
        assert_int_equal(tcb_cc_net_import(back, bin, man, &err), TCB_ERR_INPUT);
        print_message("  refused: %s\n", err.msg);
        if (!strstr(err.msg, key[k]) || !strstr(err.msg, man)) fail_msg("expected %s and %s in: %s", key[k], man, err.msg);
        tcb_cc_net_free(back);
    }
    tcb_cc_net_free(net);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_param_count),
        cmocka_unit_test(test_layout),
        cmocka_unit_test(test_init),
        cmocka_unit_test(test_encoder_train),
        cmocka_unit_test(test_encoder_eval),
        cmocka_unit_test(test_count_again),
        cmocka_unit_test(test_decoder_train),
        cmocka_unit_test(test_decoder_eval),
        cmocka_unit_test(test_decoder_residual),
        cmocka_unit_test(test_network_grad),
        cmocka_unit_test_setup_teardown(test_export_import, tu_setup_tmpdir, tu_teardown_tmpdir),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
