/* CC's decoder: the parameter predictor and the meta-MLP it parameterises
 * (the CC code's MetaVector and MetaPointGenCon2 with Meta_FC_Layer_2;
 * auxiliary/model.py), deforming B source clouds of N points given the
 * latent codes of the sources and of the targets:
 *
 *   lat [B][2Z] = [z_X, z_Y] → fc1 → bn1 → ReLU → fc2 → bn2 → ReLU → fc3
 *                            → θ [B][K]
 *   h_0 = x [B·N][3]; per meta layer l (W_b, b_b: shape b's slice of θ):
 *       u = h + b_b            (per shape, broadcast over its points)
 *       v = u·(W_b + I)        (per shape, row vectors)
 *       r = ReLU(bn0(v))       (bn0 over all B·N points: shapes mix)
 *       o = ReLU(bn1(conv(r))), last layer o = tanh(conv(r))
 *   out [B][N][3] = 2·o_L, or x + 2·o_L with dims.residual
 *
 * The gradient reaches θ through W_b and b_b, and the latents through θ;
 * the source points are data (no input gradient; the residual's x too). */
#ifndef TCB_CC_DEFORM_H
#define TCB_CC_DEFORM_H

#include "methods/cycle/net.h"

/* One forward's record (what backward needs) and its output. The source
 * points are borrowed and must stay unchanged until the backward. */
typedef struct tcb_cc_deform_cache {
    int B, N, Z, n_meta;
    size_t K;
    const float *x;               /* [B·N][3] */
    float *lat;                   /* [B][2Z] */
    float *xq1, *q1;              /* [B][Z] predictor bn1's x̂, and after ReLU */
    float *xq2, *q2;              /* [B][Z/2] */
    float *theta;                 /* [B][K] the predicted meta-MLP weights */
    float *u[TCB_CC_MAX_META];    /* [B·N][din] */
    float *xh0[TCB_CC_MAX_META];  /* [B·N][din] */
    float *r[TCB_CC_MAX_META];    /* [B·N][din] */
    float *xh1[TCB_CC_MAX_META];  /* [B·N][dout], NULL on the last layer */
    float *o[TCB_CC_MAX_META];    /* [B·N][dout] */
    float *stats;                 /* per batch norm its rstd, mean, biased variance: */
    float *sq1, *sq2;             /*   the predictor's bn1, bn2 (views into stats) */
    float *s0[TCB_CC_MAX_META];   /*   each meta layer's bn0 */
    float *s1[TCB_CC_MAX_META];   /*   and bn1 (NULL on the last layer) */
    float *out;                   /* [B·N][3] the deformed points */
} tcb_cc_deform_cache;

int tcb_cc_deform_cache_alloc(tcb_cc_deform_cache *c, const tcb_cc_net *net, int B, int N, tcb_error *err);
void tcb_cc_deform_cache_free(tcb_cc_deform_cache *c);

/* Floats of scratch a forward or backward of B shapes of N points needs. */
size_t tcb_cc_deform_scratch_floats(const tcb_cc_net *net, int B, int N);

/* zx, zy [B][Z] (source and target codes), x [B][N][3] → c->out. train as
 * for the encoder (batch statistics and moving running statistics, or the
 * running statistics). */
void tcb_cc_deform_forward(const tcb_cc_net *net, tcb_cc_deform_cache *c, float *scratch, const float *zx,
                           const float *zy, const float *x, int train);

/* net->grads += ∂L/∂params of the predictor and meta layers, and dzx, dzy
 * [B][Z] += ∂L/∂z_X, ∂L/∂z_Y, from dout [B][N][3] = ∂L/∂out, through the
 * training forward recorded in c. */
void tcb_cc_deform_backward(tcb_cc_net *net, tcb_cc_deform_cache *c, float *scratch, const float *dout,
                            float *dzx, float *dzy);

#endif
