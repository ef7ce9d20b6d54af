/* DynoSurf's deformer (methods/dynosurf/deformer.h). */
#include "methods/dynosurf/deformer.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "neural/posenc.h"
#include "neural/so3.h"
#include "tcb/geometry.h"
#include "tcb/rng.h"

enum { K = DYNO_CONTROL_POINTS };

_Static_assert(DYNO_TRANSFORM_IN == 4 * (1 + 2 * DYNO_TIME_FREQS), "the transform's encoding");

size_t dyno_deformer_blend_offset(void)
{
    return 3 * K + tcb_mlp_size(DYNO_TRANSFORM_IN, DYNO_DEFORM_WIDTH, DYNO_TRANSFORM_OUT, DYNO_DEFORM_LAYERS);
}

size_t dyno_deformer_size(void)
{
    return dyno_deformer_blend_offset() + tcb_mlp_size(DYNO_BLEND_IN, DYNO_DEFORM_WIDTH, 1, DYNO_DEFORM_LAYERS);
}

void dyno_deformer_bind(dyno_deformer *d, float *params)
{
    d->control = params;
    size_t offset = 3 * K;
    tcb_mlp_bind(&d->transform, params, &offset, DYNO_TRANSFORM_IN, DYNO_DEFORM_WIDTH, DYNO_TRANSFORM_OUT,
                 DYNO_DEFORM_LAYERS, 0);
    tcb_mlp_bind(&d->blend, params, &offset, DYNO_BLEND_IN, DYNO_DEFORM_WIDTH, 1, DYNO_DEFORM_LAYERS, 0);
}

int dyno_deformer_init(const dyno_deformer *d, const float *grid_verts, int nv, struct tcb_rng *rng, tcb_error *err)
{
    if (nv < K) return tcb_fail(err, TCB_ERR_INPUT, "dynosurf: a grid of %d vertices for %d control points", nv, K);
    tcb_mlp_init(&d->transform, rng);
    int32_t idx[K];
    int rc = tcb_farthest_points(grid_verts, nv, K, (int)tcb_rng_below(rng, (uint32_t)nv), idx, err);
    if (rc) return rc;
    for (int k = 0; k < K; k++) memcpy(d->control + 3 * k, grid_verts + 3 * (size_t)idx[k], 3 * sizeof(float));
    tcb_mlp_init(&d->blend, rng);
    return TCB_OK;
}

/* ---- blend weights ---- */

int dyno_blend_alloc(dyno_blend *b, int capacity, tcb_error *err)
{
    memset(b, 0, sizeof *b);
    b->capacity = capacity;
    size_t rows = (size_t)capacity * K;
    b->in = malloc(rows * DYNO_BLEND_IN * sizeof(float));
    b->din = malloc(rows * DYNO_BLEND_IN * sizeof(float));
    b->logit = malloc(rows * sizeof(float)), b->dlogit = malloc(rows * sizeof(float));
    b->w = malloc(rows * sizeof(float)), b->dw = malloc(rows * sizeof(float));
    if (b->in && b->din && b->logit && b->dlogit && b->w && b->dw &&
        !tcb_mlp_acts_alloc(&b->acts, DYNO_DEFORM_WIDTH, DYNO_DEFORM_LAYERS, (int)rows, err))
        return TCB_OK;
    dyno_blend_free(b);
    return tcb_fail(err, TCB_ERR_NOMEM, "dynosurf: out of memory for the blend weights of %d points", capacity);
}

void dyno_blend_free(dyno_blend *b)
{
    free(b->in), free(b->din), free(b->logit), free(b->dlogit), free(b->w), free(b->dw);
    tcb_mlp_acts_free(&b->acts);
    memset(b, 0, sizeof *b);
}

/* w [K] = softmax(g [K]) */
static void softmax(const float *g, float *w)
{
    float top = g[0];
    for (int k = 1; k < K; k++) top = fmaxf(top, g[k]);
    double z = 0;
    for (int k = 0; k < K; k++) z += w[k] = expf(g[k] - top);
    for (int k = 0; k < K; k++) w[k] = (float)(w[k] / z);
}

void dyno_blend_forward(const dyno_deformer *d, dyno_blend *b, const float *x, int n)
{
    b->n = n;
    for (size_t i = 0; i < (size_t)n; i++)
        for (int k = 0; k < K; k++) {
            float *in = b->in + (i * K + k) * DYNO_BLEND_IN;
            for (int c = 0; c < 3; c++) in[c] = x[3 * i + c], in[3 + c] = x[3 * i + c] - d->control[3 * k + c];
        }
    tcb_mlp_forward(&d->blend, &b->acts, b->in, n * K, b->logit);
    for (size_t i = 0; i < (size_t)n; i++) softmax(b->logit + i * K, b->w + i * K);
}

void dyno_blend_backward(const dyno_deformer *d, const dyno_deformer *grad, dyno_blend *b)
{
    int n = b->n;
    for (size_t i = 0; i < (size_t)n; i++) { /* through the softmax: w ⊙ (dw − Σ w dw) */
        const float *w = b->w + i * K, *dw = b->dw + i * K;
        double dot = 0;
        for (int k = 0; k < K; k++) dot += (double)w[k] * dw[k];
        for (int k = 0; k < K; k++) b->dlogit[i * K + k] = (float)(w[k] * (dw[k] - dot));
    }
    tcb_mlp_backward(&d->blend, &grad->blend, &b->acts, b->in, b->dlogit, b->din);
    for (size_t i = 0; i < (size_t)n; i++) /* the input's x − c_k part */
        for (int k = 0; k < K; k++)
            for (int c = 0; c < 3; c++) grad->control[3 * k + c] -= b->din[(i * K + k) * DYNO_BLEND_IN + 3 + c];
}

void dyno_blend_gaussian(const dyno_deformer *d, const float *x, int n, float *w)
{
    const double scale = 1.0 / (2 * DYNO_BLEND_SIGMA * DYNO_BLEND_SIGMA);
    for (size_t i = 0; i < (size_t)n; i++) {
        float g[K];
        for (int k = 0; k < K; k++) {
            double s = 0;
            for (int c = 0; c < 3; c++) {
                double e = (double)x[3 * i + c] - d->control[3 * k + c];
                s += e * e;
            }
            g[k] = (float)(-s * scale);
        }
        softmax(g, w + i * K);
    }
}

double dyno_blend_pretrain_loss(const dyno_deformer *d, const dyno_deformer *grad, dyno_blend *b, const float *x,
                                int n)
{
    dyno_blend_forward(d, b, x, n);
    dyno_blend_gaussian(d, x, n, b->dw); /* the target, then overwritten by the gradient */
    double loss = 0, scale = 1.0 / ((double)n * K);
    for (size_t i = 0; i < (size_t)n * K; i++) {
        double r = (double)b->w[i] - b->dw[i];
        loss += r * r * scale;
        b->dw[i] = (float)(2 * r * scale);
    }
    dyno_blend_backward(d, grad, b);
    return loss;
}

/* ---- per-frame transforms ---- */

int dyno_transforms_alloc(dyno_transforms *tr, int capacity, tcb_error *err)
{
    memset(tr, 0, sizeof *tr);
    tr->capacity = capacity;
    size_t rows = (size_t)capacity * K;
    tr->in = malloc(rows * DYNO_TRANSFORM_IN * sizeof(float)), tr->din = malloc(rows * DYNO_TRANSFORM_IN * sizeof(float));
    tr->raw = malloc(rows * 6 * sizeof(float)), tr->draw = malloc(rows * 6 * sizeof(float));
    tr->R = malloc(rows * 9 * sizeof(float)), tr->dR = malloc(rows * 9 * sizeof(float));
    tr->tc = malloc(rows * 4 * sizeof(float)), tr->dtc = malloc(rows * 4 * sizeof(float));
    if (tr->in && tr->din && tr->raw && tr->draw && tr->R && tr->dR && tr->tc && tr->dtc &&
        !tcb_mlp_acts_alloc(&tr->acts, DYNO_DEFORM_WIDTH, DYNO_DEFORM_LAYERS, (int)rows, err))
        return TCB_OK;
    dyno_transforms_free(tr);
    return tcb_fail(err, TCB_ERR_NOMEM, "dynosurf: out of memory for the transforms of %d frames", capacity);
}

void dyno_transforms_free(dyno_transforms *tr)
{
    free(tr->in), free(tr->din), free(tr->raw), free(tr->draw), free(tr->R), free(tr->dR), free(tr->tc), free(tr->dtc);
    tcb_mlp_acts_free(&tr->acts);
    memset(tr, 0, sizeof *tr);
}

void dyno_transforms_forward(const dyno_deformer *d, dyno_transforms *tr, const int *frames, int n)
{
    tr->n_frames = n;
    int rows = n * K;
    for (int f = 0; f < n; f++)
        for (int k = 0; k < K; k++) {
            float *r = tr->tc + 4 * (f * K + k);
            r[0] = (float)frames[f];
            for (int c = 0; c < 3; c++) r[1 + c] = d->control[3 * k + c];
        }
    tcb_posenc_forward(tr->tc, rows, 4, DYNO_TIME_FREQS, tr->in);
    tcb_mlp_forward(&d->transform, &tr->acts, tr->in, rows, tr->raw);
    for (int r = 0; r < rows; r++) tcb_so3_exp_forward(tr->R + 9 * r, tr->raw + 6 * r, 1);
}

void dyno_transforms_backward(const dyno_deformer *d, const dyno_deformer *grad, dyno_transforms *tr)
{
    int rows = tr->n_frames * K;
    for (int r = 0; r < rows; r++) {
        float dr[3];
        tcb_so3_exp_backward(dr, tr->dR + 9 * r, tr->raw + 6 * r, 1);
        for (int c = 0; c < 3; c++) tr->draw[6 * r + c] += dr[c];
    }
    tcb_mlp_backward(&d->transform, &grad->transform, &tr->acts, tr->in, tr->draw, tr->din);
    tcb_posenc_backward(tr->tc, tr->din, rows, 4, DYNO_TIME_FREQS, tr->dtc);
    for (int r = 0; r < rows; r++) /* the c_k part of (t, c_k) */
        for (int c = 0; c < 3; c++) grad->control[3 * (r % K) + c] += tr->dtc[4 * r + 1 + c];
}

/* ---- the blend of rigid motions ---- */

void dyno_deform_apply(const float *x, int n, const float *w, const float *R, const float *raw, float *X)
{
    for (size_t i = 0; i < (size_t)n; i++) {
        const float *p = x + 3 * i;
        double acc[3] = {0, 0, 0};
        for (int k = 0; k < K; k++) {
            const float *Rk = R + 9 * k, *T = raw + 6 * k + 3;
            double wk = w[i * K + k];
            for (int a = 0; a < 3; a++)
                acc[a] += wk * ((double)Rk[3 * a] * p[0] + (double)Rk[3 * a + 1] * p[1] + (double)Rk[3 * a + 2] * p[2] + T[a]);
        }
        for (int a = 0; a < 3; a++) X[3 * i + a] = (float)acc[a];
    }
}

void dyno_deform_apply_backward(const float *x, int n, const float *w, const float *R, const float *raw,
                                const float *dX, float *dR, float *draw, float *dw)
{
    for (size_t i = 0; i < (size_t)n; i++) {
        const float *p = x + 3 * i, *g = dX + 3 * i;
        for (int k = 0; k < K; k++) {
            const float *Rk = R + 9 * k, *T = raw + 6 * k + 3;
            float wk = w[i * K + k];
            double dot = 0;
            for (int a = 0; a < 3; a++) {
                double y = (double)Rk[3 * a] * p[0] + (double)Rk[3 * a + 1] * p[1] + (double)Rk[3 * a + 2] * p[2] + T[a];
                dot += y * g[a];
                for (int b = 0; b < 3; b++) dR[9 * k + 3 * a + b] += wk * g[a] * p[b];
                draw[6 * k + 3 + a] += wk * g[a];
            }
            dw[i * K + k] += (float)dot;
        }
    }
}
