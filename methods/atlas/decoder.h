/* One patch decoder of the atlas family (reference-protocol §2.2, §2.4): an
 * MLP on [u, v, z] (UV first), widths (C+2) → (C+2) → (C+2)/2 → (C+2)/4 → 3
 * with integer division as PyTorch (1026 → 1026 → 513 → 256 → 3 at C = 1024),
 * Softplus on the hidden layers, linear output. It maps the unit square to
 * one patch φ of the surface and, by forward-mode tangents, also gives the
 * Jacobian columns φ_u = ∂φ/∂u and φ_v = ∂φ/∂v in the same pass.
 *
 * Work layout: nz latent codes (the batch's shapes) decode the same m UV
 * samples (the batch shares its UV, reference-protocol §2.3). Stacked buffers
 * are [3][nz][m] rows (layers.h): the values of every (shape, sample), then
 * their ∂/∂u, then their ∂/∂v, so each hidden layer is ONE sgemm over 3·nz·m
 * rows. With nt = 0 only the value rows exist (no tangents wanted).
 *
 * Layer 1 is split: its z part s_z = W1[:, 2:]·z + b1 is computed once per
 * (shape, patch), its uv part is a fused rank-2 update per sample, and its
 * tangents are the constant columns W1[:, 0] and W1[:, 1]. */
#ifndef TCB_ATLAS_DECODER_H
#define TCB_ATLAS_DECODER_H

#include "neural/layers.h"
#include "tcb/error.h"

#define TCB_ATLAS_DEC_LAYERS 4

typedef struct tcb_atlas_decoder {
    tcb_linear l[TCB_ATLAS_DEC_LAYERS];
} tcb_atlas_decoder;

/* in/out widths of layer k for latent size C. */
void tcb_atlas_decoder_dims(int C, int k, int *in, int *out);

/* What backward needs from one patch's forward (H1, H2, H3 = the hidden
 * widths, R = nz·m value rows). */
typedef struct tcb_atlas_decoder_cache {
    int nz, m, C, nt;
    float *wuv; /* [2][H1] W1[:, 0] and W1[:, 1], contiguous */
    float *sz;  /* [nz][H1] the per-shape part of layer 1's pre-activation */
    float *s1;  /* [R][H1] layer 1 pre-activations (its tangents are wuv) */
    float *a1;  /* [3R][H1] layer 1 activations, stacked */
    float *x2;  /* [3R][H2] layer 2 pre-activations, stacked */
    float *a2;  /* [3R][H2] */
    float *x3;  /* [3R][H3] */
    float *a3;  /* [3R][H3] */
} tcb_atlas_decoder_cache;

/* Backward scratch: any patch's backward can use it, one at a time. */
typedef struct tcb_atlas_decoder_scratch {
    float *da;  /* [3R][H1] */
    float *dx;  /* [3R][H1] */
    float *dsz; /* [nz][H1] */
    float *dw;  /* [2][H1] */
} tcb_atlas_decoder_scratch;

int tcb_atlas_decoder_cache_alloc(tcb_atlas_decoder_cache *c, int nz, int m, int C,
                                  tcb_error *err);
void tcb_atlas_decoder_cache_free(tcb_atlas_decoder_cache *c);
int tcb_atlas_decoder_scratch_alloc(tcb_atlas_decoder_scratch *s, int nz, int m, int C,
                                    tcb_error *err);
void tcb_atlas_decoder_scratch_free(tcb_atlas_decoder_scratch *s);

/* z [nz][C], uv [m][2] → out [(1+nt)·nz·m][3] stacked: φ, then φ_u and φ_v
 * if nt = 2 (nt is 0 or 2). */
void tcb_atlas_decoder_forward(const tcb_atlas_decoder *d, tcb_atlas_decoder_cache *c,
                               const float *z, const float *uv, int nt, float *out);

/* Reverse mode through values and tangents from dout [(1+nt)·nz·m][3] =
 * ∂L/∂out (nt ≤ the forward's nt; nt = 0 when L does not depend on φ_u, φ_v,
 * which then skips the tangent rows). Accumulates the parameter gradients
 * into `grad`, dz [nz][C] += ∂L/∂z and, if duv is not NULL, duv [m][2] +=
 * ∂L/∂uv (summed over the shapes, which share the samples). */
void tcb_atlas_decoder_backward(const tcb_atlas_decoder *d, const tcb_atlas_decoder *grad,
                                const tcb_atlas_decoder_cache *c,
                                tcb_atlas_decoder_scratch *s, const float *z, const float *uv,
                                const float *dout, int nt, float *dz, float *duv);

#endif
