#include "methods/cycle/encoder.h"

#include <stdlib.h>
#include <string.h>

enum { BN1, BN2, BN3, BNF, N_BN };

/* Width of batch norm k, and where its stats (rstd, mean, var: 3 × width)
 * start inside c->stats. */
static int bn_width(int C, int Z, int k)
{
    const int w[N_BN] = {TCB_CC_ENC1, TCB_CC_ENC2, C, Z};
    return w[k];
}

static float *stats_of(const tcb_cc_encoder_cache *c, int k)
{
    size_t at = 0;
    for (int j = 0; j < k; j++) at += 3 * (size_t)bn_width(c->C, c->Z, j);
    return c->stats + at;
}

int tcb_cc_encoder_cache_alloc(tcb_cc_encoder_cache *c, const tcb_cc_dims *d, int B, int N, tcb_error *err)
{
    memset(c, 0, sizeof *c);
    c->B = B, c->N = N, c->C = d->C, c->Z = d->Z;
    size_t R = (size_t)B * N, nstats = 3 * (size_t)(TCB_CC_ENC1 + TCB_CC_ENC2 + d->C + d->Z);
    c->xh1 = malloc(R * TCB_CC_ENC1 * sizeof(float));
    c->h1 = malloc(R * TCB_CC_ENC1 * sizeof(float));
    c->xh2 = malloc(R * TCB_CC_ENC2 * sizeof(float));
    c->h2 = malloc(R * TCB_CC_ENC2 * sizeof(float));
    c->a3 = malloc(R * d->C * sizeof(float));
    c->mlo3 = malloc((size_t)d->C * sizeof(float));
    c->arg = malloc((size_t)B * d->C * sizeof(int32_t));
    c->g = malloc((size_t)B * d->C * sizeof(float));
    c->xhf = malloc((size_t)B * d->Z * sizeof(float));
    c->z = malloc((size_t)B * d->Z * sizeof(float));
    c->stats = malloc(nstats * sizeof(float));
    if (!c->xh1 || !c->h1 || !c->xh2 || !c->h2 || !c->a3 || !c->mlo3 || !c->arg || !c->g || !c->xhf || !c->z || !c->stats) {
        tcb_cc_encoder_cache_free(c);
        return tcb_fail(err, TCB_ERR_NOMEM, "cc encoder: out of memory for %d clouds of %d points", B, N);
    }
    return TCB_OK;
}

void tcb_cc_encoder_cache_free(tcb_cc_encoder_cache *c)
{
    free(c->xh1), free(c->h1), free(c->xh2), free(c->h2), free(c->a3), free(c->mlo3);
    free(c->arg), free(c->g), free(c->xhf), free(c->z), free(c->stats);
    memset(c, 0, sizeof *c);
}

size_t tcb_cc_encoder_scratch_floats(const tcb_cc_dims *d, int B, int N)
{
    size_t R = (size_t)B * N;
    return R * ((size_t)d->C + TCB_CC_ENC2 + TCB_CC_ENC1) + (size_t)B * ((size_t)d->C + d->Z);
}

/* y = BN(x) over n rows in either mode, recording x̂ and the statistics of
 * a training forward into xhat and st (rstd, mean, var). */
static void norm(const tcb_batchnorm *bn, float *y, float *xhat, float *st, const float *x, int n, int train,
                 int relu)
{
    if (!train) {
        tcb_batchnorm_forward_eval(bn, y, x, n, relu);
        return;
    }
    int C = bn->C;
    tcb_batchnorm_forward_train(bn, y, xhat, st, st + C, st + 2 * C, x, n, relu);
    tcb_batchnorm_update_running(bn, st + C, st + 2 * C, n);
}

void tcb_cc_encoder_forward(const tcb_cc_encoder *e, tcb_cc_encoder_cache *c, float *scratch,
                            const float *clouds, int train)
{
    int B = c->B, N = c->N, R = B * N, C = c->C, Z = c->Z;
    float *pre = scratch; /* [R][max(C, 128)] pre-activations */
    c->x = clouds;
    tcb_linear_forward(pre, clouds, e->conv1.W, e->conv1.b, R, 0, 3, TCB_CC_ENC1);
    norm(&e->bn1, c->h1, c->xh1, stats_of(c, BN1), pre, R, train, 1);
    tcb_linear_forward(pre, c->h1, e->conv2.W, e->conv2.b, R, 0, TCB_CC_ENC1, TCB_CC_ENC2);
    norm(&e->bn2, c->h2, c->xh2, stats_of(c, BN2), pre, R, train, 1);
    if (train) { /* bn3 and the pool fused: BN(a3) is never written */
        float *st = stats_of(c, BN3);
        tcb_linear_forward(c->a3, c->h2, e->conv3.W, e->conv3.b, R, 0, TCB_CC_ENC2, C);
        tcb_batchnorm_maxpool_forward_train(&e->bn3, c->g, c->arg, st, st + C, c->mlo3, st + 2 * C, c->a3, B, N);
        tcb_batchnorm_update_running(&e->bn3, st + C, st + 2 * C, R);
    } else {
        tcb_linear_forward(pre, c->h2, e->conv3.W, e->conv3.b, R, 0, TCB_CC_ENC2, C);
        tcb_batchnorm_forward_eval(&e->bn3, pre, pre, R, 0);
        tcb_maxpool_forward(c->g, c->arg, pre, B, N, C);
    }
    tcb_linear_forward(c->z, c->g, e->fc.W, e->fc.b, B, 0, C, Z);
    norm(&e->bnf, c->z, c->xhf, stats_of(c, BNF), c->z, B, train, 1);
}

void tcb_cc_encoder_count_again(const tcb_cc_encoder *e, const tcb_cc_encoder_cache *c)
{
    const tcb_batchnorm *bns[N_BN] = {&e->bn1, &e->bn2, &e->bn3, &e->bnf};
    int rows[N_BN] = {c->B * c->N, c->B * c->N, c->B * c->N, c->B};
    for (int k = 0; k < N_BN; k++) {
        const float *st = stats_of(c, k);
        int C = bns[k]->C;
        tcb_batchnorm_update_running(bns[k], st + C, st + 2 * C, rows[k]);
    }
}

void tcb_cc_encoder_backward(const tcb_cc_encoder *e, const tcb_cc_encoder *grad, tcb_cc_encoder_cache *c,
                             float *scratch, const float *dz)
{
    int B = c->B, N = c->N, R = B * N, C = c->C, Z = c->Z;
    float *d3 = scratch;                           /* [R][C] */
    float *d2 = d3 + (size_t)R * C;                /* [R][128] */
    float *d1 = d2 + (size_t)R * TCB_CC_ENC2;      /* [R][64] */
    float *dg = d1 + (size_t)R * TCB_CC_ENC1;      /* [B][C] */
    float *df = dg + (size_t)B * C;                /* [B][Z] */
    /* every layer here feeds a training-mode batch norm, which subtracts
     * the batch mean: the biases' gradients are exactly zero (PyTorch
     * computes them as rounding noise), so they are not summed (db NULL) */
    tcb_batchnorm_backward(&e->bnf, &grad->bnf, df, dz, c->z, c->xhf, stats_of(c, BNF), B);
    tcb_linear_backward(dg, grad->fc.W, NULL, df, c->g, e->fc.W, B, 0, C, Z);
    const float *st = stats_of(c, BN3);
    tcb_batchnorm_maxpool_backward(&e->bn3, &grad->bn3, d3, dg, c->arg, c->a3, st, st + C, c->mlo3, B, N);
    tcb_linear_backward(d2, grad->conv3.W, NULL, d3, c->h2, e->conv3.W, R, 0, TCB_CC_ENC2, C);
    tcb_batchnorm_backward(&e->bn2, &grad->bn2, d2, d2, c->h2, c->xh2, stats_of(c, BN2), R);
    tcb_linear_backward(d1, grad->conv2.W, NULL, d2, c->h1, e->conv2.W, R, 0, TCB_CC_ENC1, TCB_CC_ENC2);
    tcb_batchnorm_backward(&e->bn1, &grad->bn1, d1, d1, c->h1, c->xh1, stats_of(c, BN1), R);
    tcb_linear_backward(NULL, grad->conv1.W, NULL, d1, c->x, e->conv1.W, R, 0, 3, TCB_CC_ENC1);
}
