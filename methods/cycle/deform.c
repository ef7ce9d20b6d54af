#include "methods/cycle/deform.h"

#include <cblas.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

static int imax(int a, int b) { return a > b ? a : b; }

/* The widest per-point activation of the meta-MLP. */
static int widest(const tcb_cc_net *net) { return imax(net->d.H, 3); }

int tcb_cc_deform_cache_alloc(tcb_cc_deform_cache *c, const tcb_cc_net *net, int B, int N, tcb_error *err)
{
    memset(c, 0, sizeof *c);
    int Z = net->d.Z;
    c->B = B, c->N = N, c->Z = Z, c->n_meta = net->n_meta, c->K = net->K;
    size_t R = (size_t)B * N, nstats = 3 * (size_t)(Z + Z / 2);
    for (int l = 0; l < c->n_meta; l++) {
        const tcb_cc_meta_layer *m = &net->p.meta[l];
        nstats += 3 * (size_t)(m->din + m->bn1.C);
    }
    int ok = (c->lat = malloc((size_t)B * 2 * Z * sizeof(float))) != NULL;
    ok &= (c->xq1 = malloc((size_t)B * Z * sizeof(float))) != NULL;
    ok &= (c->q1 = malloc((size_t)B * Z * sizeof(float))) != NULL;
    ok &= (c->xq2 = malloc((size_t)B * (Z / 2) * sizeof(float))) != NULL;
    ok &= (c->q2 = malloc((size_t)B * (Z / 2) * sizeof(float))) != NULL;
    ok &= (c->theta = malloc((size_t)B * c->K * sizeof(float))) != NULL;
    ok &= (c->stats = malloc(nstats * sizeof(float))) != NULL;
    ok &= (c->out = malloc(R * 3 * sizeof(float))) != NULL;
    for (int l = 0; ok && l < c->n_meta; l++) {
        const tcb_cc_meta_layer *m = &net->p.meta[l];
        ok &= (c->u[l] = malloc(R * m->din * sizeof(float))) != NULL;
        ok &= (c->xh0[l] = malloc(R * m->din * sizeof(float))) != NULL;
        ok &= (c->r[l] = malloc(R * m->din * sizeof(float))) != NULL;
        ok &= (c->o[l] = malloc(R * m->dout * sizeof(float))) != NULL;
        if (m->bn1.C) ok &= (c->xh1[l] = malloc(R * m->dout * sizeof(float))) != NULL;
    }
    if (!ok) {
        tcb_cc_deform_cache_free(c);
        return tcb_fail(err, TCB_ERR_NOMEM, "cc decoder: out of memory for %d shapes of %d points", B, N);
    }
    float *st = c->stats;
    c->sq1 = st, st += 3 * (size_t)Z;
    c->sq2 = st, st += 3 * (size_t)(Z / 2);
    for (int l = 0; l < c->n_meta; l++) {
        const tcb_cc_meta_layer *m = &net->p.meta[l];
        c->s0[l] = st, st += 3 * (size_t)m->din;
        if (m->bn1.C) c->s1[l] = st, st += 3 * (size_t)m->bn1.C;
    }
    return TCB_OK;
}

void tcb_cc_deform_cache_free(tcb_cc_deform_cache *c)
{
    free(c->lat), free(c->xq1), free(c->q1), free(c->xq2), free(c->q2), free(c->theta);
    free(c->stats), free(c->out);
    for (int l = 0; l < c->n_meta; l++) free(c->u[l]), free(c->xh0[l]), free(c->r[l]), free(c->o[l]), free(c->xh1[l]);
    memset(c, 0, sizeof *c);
}

size_t tcb_cc_deform_scratch_floats(const tcb_cc_net *net, int B, int N)
{
    return 3 * (size_t)B * N * widest(net) + (size_t)B * (net->K + 4 * (size_t)net->d.Z);
}

/* y = ReLU(BN(x)) (every batch norm of the decoder has its ReLU) in either
 * mode; a training forward records x̂ and the stats (rstd, mean, var) and
 * moves the running statistics. */
static void norm(const tcb_batchnorm *bn, float *y, float *xhat, float *st, const float *x, int n, int train)
{
    if (!train) {
        tcb_batchnorm_forward_eval(bn, y, x, n, 1);
        return;
    }
    int C = bn->C;
    tcb_batchnorm_forward_train(bn, y, xhat, st, st + C, st + 2 * C, x, n, 1);
    tcb_batchnorm_update_running(bn, st + C, st + 2 * C, n);
}

/* ---- forward ---- */

static void predictor_forward(const tcb_cc_predictor *p, tcb_cc_deform_cache *c, const float *zx,
                              const float *zy, int train)
{
    int B = c->B, Z = c->Z;
    for (int b = 0; b < B; b++) {
        memcpy(c->lat + (size_t)b * 2 * Z, zx + (size_t)b * Z, (size_t)Z * sizeof(float));
        memcpy(c->lat + (size_t)b * 2 * Z + Z, zy + (size_t)b * Z, (size_t)Z * sizeof(float));
    }
    tcb_linear_forward(c->q1, c->lat, p->fc1.W, p->fc1.b, B, 0, 2 * Z, Z);
    norm(&p->bn1, c->q1, c->xq1, c->sq1, c->q1, B, train);
    tcb_linear_forward(c->q2, c->q1, p->fc2.W, p->fc2.b, B, 0, Z, Z / 2);
    norm(&p->bn2, c->q2, c->xq2, c->sq2, c->q2, B, train);
    tcb_linear_forward(c->theta, c->q2, p->fc3.W, p->fc3.b, B, 0, Z / 2, (int)c->K);
}

/* u = h + b_b and v = u·(W_b + I), shape by shape; v [B·N][din]. Shapes run
 * in parallel with single-threaded GEMMs (OpenBLAS sees the parallel
 * region): each is too small to split well. */
static void predicted_forward(const tcb_cc_meta_layer *m, tcb_cc_deform_cache *c, float *u, float *v,
                              const float *h)
{
    int N = c->N, d = m->din;
#pragma omp parallel for schedule(static)
    for (int b = 0; b < c->B; b++) {
        const float *th = c->theta + (size_t)b * c->K, *W = th + m->w_at, *bias = th + m->b_at;
        size_t at = (size_t)b * N * d;
        for (int n = 0; n < N; n++)
            for (int i = 0; i < d; i++) u[at + (size_t)n * d + i] = h[at + (size_t)n * d + i] + bias[i];
        memcpy(v + at, u + at, (size_t)N * d * sizeof(float));
        cblas_sgemm(CblasRowMajor, CblasNoTrans, CblasNoTrans, N, d, d, 1.0f, u + at, d, W, d, 1.0f, v + at, d);
    }
}

void tcb_cc_deform_forward(const tcb_cc_net *net, tcb_cc_deform_cache *c, float *scratch, const float *zx,
                           const float *zy, const float *x, int train)
{
    int R = c->B * c->N;
    float *v = scratch, *pre = scratch + (size_t)R * widest(net);
    c->x = x;
    predictor_forward(&net->p.pred, c, zx, zy, train);
    const float *h = x;
    for (int l = 0; l < c->n_meta; l++) {
        const tcb_cc_meta_layer *m = &net->p.meta[l];
        predicted_forward(m, c, c->u[l], v, h);
        norm(&m->bn0, c->r[l], c->xh0[l], c->s0[l], v, R, train);
        if (m->bn1.C) {
            tcb_linear_forward(pre, c->r[l], m->conv.W, m->conv.b, R, 0, m->din, m->dout);
            norm(&m->bn1, c->o[l], c->xh1[l], c->s1[l], pre, R, train);
        } else {
            tcb_linear_forward(c->o[l], c->r[l], m->conv.W, m->conv.b, R, 0, m->din, m->dout);
            for (size_t k = 0; k < (size_t)R * m->dout; k++) c->o[l][k] = tanhf(c->o[l][k]);
        }
        h = c->o[l];
    }
    for (size_t k = 0; k < (size_t)R * 3; k++) c->out[k] = 2.0f * h[k] + (net->d.residual ? x[k] : 0.0f);
}

/* ---- backward ---- */

/* From dv [B·N][din] = ∂L/∂v: dθ_b's W slice = u_bᵀ·dv_b, du_b = dv_b·(W_b +
 * I)ᵀ (into du, which is ∂L/∂h as h + b_b = u), dθ_b's b slice = Σ_n du_b. */
static void predicted_backward(const tcb_cc_meta_layer *m, tcb_cc_deform_cache *c, float *dtheta, float *du,
                               const float *dv, const float *u)
{
    int N = c->N, d = m->din;
#pragma omp parallel for schedule(static)
    for (int b = 0; b < c->B; b++) {
        const float *W = c->theta + (size_t)b * c->K + m->w_at;
        float *dt = dtheta + (size_t)b * c->K;
        size_t at = (size_t)b * N * d;
        cblas_sgemm(CblasRowMajor, CblasTrans, CblasNoTrans, d, d, N, 1.0f, u + at, d, dv + at, d, 0.0f,
                    dt + m->w_at, d);
        memcpy(du + at, dv + at, (size_t)N * d * sizeof(float));
        cblas_sgemm(CblasRowMajor, CblasNoTrans, CblasTrans, N, d, d, 1.0f, dv + at, d, W, d, 1.0f, du + at, d);
        for (int i = 0; i < d; i++) {
            double s = 0;
            for (int n = 0; n < N; n++) s += du[at + (size_t)n * d + i];
            dt[m->b_at + i] = (float)s;
        }
    }
}

static void predictor_backward(const tcb_cc_predictor *p, const tcb_cc_predictor *g, tcb_cc_deform_cache *c,
                               float *scratch, const float *dtheta, float *dzx, float *dzy)
{
    int B = c->B, Z = c->Z;
    float *d2 = scratch, *d1 = d2 + (size_t)B * Z, *dlat = d1 + (size_t)B * Z;
    /* fc1 and fc2 feed training-mode batch norms: their biases' gradients
     * are exactly zero (the batch mean is subtracted), not summed */
    tcb_linear_backward(d2, g->fc3.W, g->fc3.b, dtheta, c->q2, p->fc3.W, B, 0, Z / 2, (int)c->K);
    tcb_batchnorm_backward(&p->bn2, &g->bn2, d2, d2, c->q2, c->xq2, c->sq2, B);
    tcb_linear_backward(d1, g->fc2.W, NULL, d2, c->q1, p->fc2.W, B, 0, Z, Z / 2);
    tcb_batchnorm_backward(&p->bn1, &g->bn1, d1, d1, c->q1, c->xq1, c->sq1, B);
    tcb_linear_backward(dlat, g->fc1.W, NULL, d1, c->lat, p->fc1.W, B, 0, 2 * Z, Z);
    for (int b = 0; b < B; b++)
        for (int j = 0; j < Z; j++) {
            dzx[(size_t)b * Z + j] += dlat[(size_t)b * 2 * Z + j];
            dzy[(size_t)b * Z + j] += dlat[(size_t)b * 2 * Z + Z + j];
        }
}

void tcb_cc_deform_backward(tcb_cc_net *net, tcb_cc_deform_cache *c, float *scratch, const float *dout,
                            float *dzx, float *dzy)
{
    int R = c->B * c->N, w = widest(net);
    float *dh = scratch, *dc = dh + (size_t)R * w, *dr = dc + (size_t)R * w;
    float *dtheta = dr + (size_t)R * w, *rest = dtheta + (size_t)c->B * c->K;
    const tcb_cc_meta_layer *last = &net->p.meta[c->n_meta - 1];
    for (size_t k = 0; k < (size_t)R * 3; k++) dh[k] = 2.0f * dout[k];
    for (int l = c->n_meta - 1; l >= 0; l--) {
        const tcb_cc_meta_layer *m = &net->p.meta[l], *gm = &net->g.meta[l];
        size_t n_out = (size_t)R * m->dout;
        if (m == last)
            for (size_t k = 0; k < n_out; k++) dc[k] = dh[k] * (1.0f - c->o[l][k] * c->o[l][k]);
        else
            tcb_batchnorm_backward(&m->bn1, &gm->bn1, dc, dh, c->o[l], c->xh1[l], c->s1[l], R);
        /* a conv followed by bn1 has an exactly zero bias gradient: not summed */
        tcb_linear_backward(dr, gm->conv.W, m == last ? gm->conv.b : NULL, dc, c->r[l], m->conv.W, R, 0, m->din,
                            m->dout);
        tcb_batchnorm_backward(&m->bn0, &gm->bn0, dr, dr, c->r[l], c->xh0[l], c->s0[l], R);
        predicted_backward(m, c, dtheta, dh, dr, c->u[l]);
    }
    predictor_backward(&net->p.pred, &net->g.pred, c, rest, dtheta, dzx, dzy);
}
