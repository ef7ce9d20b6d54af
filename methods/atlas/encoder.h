/* The PointNet encoder of the atlas family (reference-protocol §2.1): per
 * point 3→64 ReLU →128 ReLU →C (no activation), max-pool over the points,
 * then C→C ReLU, C→C ReLU. No batch norm. The final ReLU makes z ≥ 0. */
#ifndef TCB_ATLAS_ENCODER_H
#define TCB_ATLAS_ENCODER_H

#include <stdint.h>

#include "neural/layers.h"
#include "tcb/error.h"

#define TCB_ATLAS_ENC_LAYERS 5

/* Layers in order: conv1 3→64, conv2 64→128, conv3 128→C (1×1 convolutions,
 * i.e. per-point linear layers), fc1 C→C, fc2 C→C. */
typedef struct tcb_atlas_encoder {
    tcb_linear l[TCB_ATLAS_ENC_LAYERS];
} tcb_atlas_encoder;

/* in/out widths of layer k for latent size C. */
void tcb_atlas_encoder_dims(int C, int k, int *in, int *out);

/* What backward needs from forward, for B clouds of N points; z is the
 * output. Rows are points, shape-major ([B][N] = B·N rows). */
typedef struct tcb_atlas_encoder_cache {
    int B, N, C;
    float *x;     /* [B·N][3] the input clouds (copied) */
    float *h1;    /* [B·N][64] after ReLU */
    float *h2;    /* [B·N][128] after ReLU */
    float *h3;    /* [B·N][C] conv3 output, pooled at once */
    float *g;     /* [B][C] max-pooled */
    int32_t *arg; /* [B][C] the point each channel's max came from */
    float *f1;    /* [B][C] after fc1 + ReLU */
    float *z;     /* [B][C] latent codes, after fc2 + ReLU */
    float *dh1;   /* [B·N][64] backward scratch */
    float *dh2;   /* [B·N][128] backward scratch */
    float *dv1;   /* [B][C] backward scratch */
    float *dv2;   /* [B][C] backward scratch */
} tcb_atlas_encoder_cache;

int tcb_atlas_encoder_cache_alloc(tcb_atlas_encoder_cache *c, int B, int N, int C,
                                  tcb_error *err);
void tcb_atlas_encoder_cache_free(tcb_atlas_encoder_cache *c);

/* clouds [B][N][3] → c->z [B][C]. */
void tcb_atlas_encoder_forward(const tcb_atlas_encoder *e, tcb_atlas_encoder_cache *c,
                               const float *clouds);

/* Gradients of every encoder parameter, accumulated into the views `grad`,
 * from dz [B][C] = ∂L/∂z. Needs the cache of the matching forward. The
 * input gradient is not computed (the clouds are data). */
void tcb_atlas_encoder_backward(const tcb_atlas_encoder *e, const tcb_atlas_encoder *grad,
                                tcb_atlas_encoder_cache *c, const float *dz);

#endif
