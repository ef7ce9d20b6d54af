#include "methods/atlas/encoder.h"

#include <stdlib.h>
#include <string.h>

#define H1 64
#define H2 128

void tcb_atlas_encoder_dims(int C, int k, int *in, int *out)
{
    const int ins[TCB_ATLAS_ENC_LAYERS] = {3, H1, H2, C, C};
    const int outs[TCB_ATLAS_ENC_LAYERS] = {H1, H2, C, C, C};
    *in = ins[k], *out = outs[k];
}

int tcb_atlas_encoder_cache_alloc(tcb_atlas_encoder_cache *c, int B, int N, int C,
                                  tcb_error *err)
{
    size_t pts = (size_t)B * N, codes = (size_t)B * C;
    memset(c, 0, sizeof *c);
    c->B = B, c->N = N, c->C = C;
    c->x = malloc(pts * 3 * sizeof(float));
    c->h1 = malloc(pts * H1 * sizeof(float));
    c->h2 = malloc(pts * H2 * sizeof(float));
    c->h3 = malloc(pts * C * sizeof(float));
    c->g = malloc(codes * sizeof(float));
    c->arg = malloc(codes * sizeof(int32_t));
    c->f1 = malloc(codes * sizeof(float));
    c->z = malloc(codes * sizeof(float));
    c->dh1 = malloc(pts * H1 * sizeof(float));
    c->dh2 = malloc(pts * H2 * sizeof(float));
    c->dv1 = malloc(codes * sizeof(float));
    c->dv2 = malloc(codes * sizeof(float));
    if (!c->x || !c->h1 || !c->h2 || !c->h3 || !c->g || !c->arg || !c->f1 || !c->z || !c->dh1 ||
        !c->dh2 || !c->dv1 || !c->dv2) {
        tcb_atlas_encoder_cache_free(c);
        return tcb_fail(err, TCB_ERR_NOMEM, "atlas encoder: out of memory for B=%d N=%d C=%d",
                        B, N, C);
    }
    return TCB_OK;
}

void tcb_atlas_encoder_cache_free(tcb_atlas_encoder_cache *c)
{
    free(c->x), free(c->h1), free(c->h2), free(c->h3), free(c->g), free(c->arg);
    free(c->f1), free(c->z), free(c->dh1), free(c->dh2), free(c->dv1), free(c->dv2);
    memset(c, 0, sizeof *c);
}

void tcb_atlas_encoder_forward(const tcb_atlas_encoder *e, tcb_atlas_encoder_cache *c,
                               const float *clouds)
{
    int B = c->B, C = c->C, pts = c->B * c->N;
    memcpy(c->x, clouds, (size_t)pts * 3 * sizeof(float));
    tcb_linear_forward(c->h1, c->x, e->l[0].W, e->l[0].b, pts, 0, 3, H1);
    tcb_relu_forward(c->h1, c->h1, (int64_t)pts * H1);
    tcb_linear_forward(c->h2, c->h1, e->l[1].W, e->l[1].b, pts, 0, H1, H2);
    tcb_relu_forward(c->h2, c->h2, (int64_t)pts * H2);
    tcb_linear_forward(c->h3, c->h2, e->l[2].W, e->l[2].b, pts, 0, H2, C);
    tcb_maxpool_forward(c->g, c->arg, c->h3, B, c->N, C);
    tcb_linear_forward(c->f1, c->g, e->l[3].W, e->l[3].b, B, 0, C, C);
    tcb_relu_forward(c->f1, c->f1, (int64_t)B * C);
    tcb_linear_forward(c->z, c->f1, e->l[4].W, e->l[4].b, B, 0, C, C);
    tcb_relu_forward(c->z, c->z, (int64_t)B * C);
}

void tcb_atlas_encoder_backward(const tcb_atlas_encoder *e, const tcb_atlas_encoder *grad,
                                tcb_atlas_encoder_cache *c, const float *dz)
{
    int B = c->B, C = c->C, pts = c->B * c->N;
    const tcb_linear *g = grad->l;
    /* fc2, fc1: dv1 and dv2 alternate as the running gradient */
    tcb_relu_backward(c->dv1, dz, c->z, (int64_t)B * C);
    tcb_linear_backward(c->dv2, g[4].W, g[4].b, c->dv1, c->f1, e->l[4].W, B, 0, C, C);
    tcb_relu_backward(c->dv2, c->dv2, c->f1, (int64_t)B * C);
    tcb_linear_backward(c->dv1, g[3].W, g[3].b, c->dv2, c->g, e->l[3].W, B, 0, C, C);
    tcb_maxpool_linear_backward(c->dh2, g[2].W, g[2].b, c->dv1, c->arg, c->h2, e->l[2].W, B,
                                      c->N, H2, C);
    tcb_relu_backward(c->dh2, c->dh2, c->h2, (int64_t)pts * H2);
    tcb_linear_backward(c->dh1, g[1].W, g[1].b, c->dh2, c->h1, e->l[1].W, pts, 0, H1, H2);
    tcb_relu_backward(c->dh1, c->dh1, c->h1, (int64_t)pts * H1);
    tcb_linear_backward(NULL, g[0].W, g[0].b, c->dh1, c->x, e->l[0].W, pts, 0, 3, H1);
}
