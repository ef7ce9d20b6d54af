/* CC's PointNet encoder with batch norm (the CC code's PointNetfeat, STN
 * off, followed by Linear + BatchNorm1d + ReLU; auxiliary/model.py,
 * model_pointnetfeat.py), over B clouds of N points:
 *
 *   per point   x [B·N][3] → conv1 → bn1 → ReLU → h1 [B·N][64]
 *                          → conv2 → bn2 → ReLU → h2 [B·N][128]
 *                          → conv3 → bn3 (no ReLU) → a3 [B·N][C]
 *   per cloud   max over the N points → g [B][C] → fc → bnf → ReLU → z [B][Z]
 *
 * In training the batch norms of the per-point layers pool their
 * statistics over all B·N points (every cloud of the batch), bnf over the B
 * clouds, as PyTorch's BatchNorm1d on [B, C, N] and [B, C]. */
#ifndef TCB_CC_ENCODER_H
#define TCB_CC_ENCODER_H

#include <stdint.h>

#include "methods/cycle/net.h"

/* One forward's record (what backward needs) and its output z. The clouds
 * are borrowed: they must stay unchanged until the backward. */
typedef struct tcb_cc_encoder_cache {
    int B, N, C, Z;
    const float *x; /* [B·N][3] */
    float *xh1, *h1; /* [B·N][64] bn1's x̂, and after ReLU */
    float *xh2, *h2; /* [B·N][128] */
    float *a3;       /* [B·N][C] conv3's output: bn3 and the pool recompute x̂ from it */
    float *mlo3;     /* [C] bn3's mean, low float part */
    int32_t *arg;    /* [B][C] the point each channel's max came from */
    float *g;        /* [B][C] max-pooled */
    float *xhf;      /* [B][Z] */
    float *z;        /* [B][Z] the latent codes */
    float *stats;    /* per batch norm (bn1, bn2, bn3, bnf) its rstd, mean, biased variance */
} tcb_cc_encoder_cache;

int tcb_cc_encoder_cache_alloc(tcb_cc_encoder_cache *c, const tcb_cc_dims *d, int B, int N, tcb_error *err);
void tcb_cc_encoder_cache_free(tcb_cc_encoder_cache *c);

/* Floats of scratch a forward or backward of B·N points needs. */
size_t tcb_cc_encoder_scratch_floats(const tcb_cc_dims *d, int B, int N);

/* clouds [B][N][3] → c->z [B][Z]. train: batch statistics, and the running
 * statistics move (PyTorch's train()); else the running statistics (eval()). */
void tcb_cc_encoder_forward(const tcb_cc_encoder *e, tcb_cc_encoder_cache *c, float *scratch,
                            const float *clouds, int train);

/* Moves the running statistics once more by the batch statistics of c's
 * training forward: the same module called again on the same clouds gives
 * the same output, so a caller reuses c and counts the call. */
void tcb_cc_encoder_count_again(const tcb_cc_encoder *e, const tcb_cc_encoder_cache *c);

/* Accumulates every parameter's gradient into `grad` from dz [B][Z] =
 * ∂L/∂z, through the training forward recorded in c. The clouds are data:
 * no input gradient. */
void tcb_cc_encoder_backward(const tcb_cc_encoder *e, const tcb_cc_encoder *grad, tcb_cc_encoder_cache *c,
                             float *scratch, const float *dz);

#endif
