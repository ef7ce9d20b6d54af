#include "methods/atlas/decoder.h"

#include <cblas.h>
#include <stdlib.h>
#include <string.h>

#include "neural/parallel.h"

void tcb_atlas_decoder_dims(int C, int k, int *in, int *out)
{
    int h1 = C + 2;
    const int ins[TCB_ATLAS_DEC_LAYERS] = {h1, h1, h1 / 2, h1 / 4};
    const int outs[TCB_ATLAS_DEC_LAYERS] = {h1, h1 / 2, h1 / 4, 3};
    *in = ins[k], *out = outs[k];
}

int tcb_atlas_decoder_cache_alloc(tcb_atlas_decoder_cache *c, int nz, int m, int C,
                                  tcb_error *err)
{
    size_t h1 = (size_t)C + 2, h2 = h1 / 2, h3 = h1 / 4, R = (size_t)nz * m;
    memset(c, 0, sizeof *c);
    c->nz = nz, c->m = m, c->C = C;
    c->wuv = malloc(2 * h1 * sizeof(float));
    c->sz = malloc(nz * h1 * sizeof(float));
    c->s1 = malloc(R * h1 * sizeof(float));
    c->a1 = malloc(3 * R * h1 * sizeof(float));
    c->x2 = malloc(3 * R * h2 * sizeof(float));
    c->a2 = malloc(3 * R * h2 * sizeof(float));
    c->x3 = malloc(3 * R * h3 * sizeof(float));
    c->a3 = malloc(3 * R * h3 * sizeof(float));
    if (!c->wuv || !c->sz || !c->s1 || !c->a1 || !c->x2 || !c->a2 || !c->x3 || !c->a3) {
        tcb_atlas_decoder_cache_free(c);
        return tcb_fail(err, TCB_ERR_NOMEM, "atlas decoder: out of memory for %d x %d samples",
                        nz, m);
    }
    return TCB_OK;
}

void tcb_atlas_decoder_cache_free(tcb_atlas_decoder_cache *c)
{
    free(c->wuv), free(c->sz), free(c->s1), free(c->a1);
    free(c->x2), free(c->a2), free(c->x3), free(c->a3);
    memset(c, 0, sizeof *c);
}

int tcb_atlas_decoder_scratch_alloc(tcb_atlas_decoder_scratch *s, int nz, int m, int C,
                                    tcb_error *err)
{
    size_t h1 = (size_t)C + 2, R = (size_t)nz * m;
    s->da = malloc(3 * R * h1 * sizeof(float));
    s->dx = malloc(3 * R * h1 * sizeof(float));
    s->dsz = malloc(nz * h1 * sizeof(float));
    s->dw = malloc(2 * h1 * sizeof(float));
    if (!s->da || !s->dx || !s->dsz || !s->dw) {
        tcb_atlas_decoder_scratch_free(s);
        return tcb_fail(err, TCB_ERR_NOMEM, "atlas decoder: out of memory for %d x %d samples",
                        nz, m);
    }
    return TCB_OK;
}

void tcb_atlas_decoder_scratch_free(tcb_atlas_decoder_scratch *s)
{
    free(s->da), free(s->dx), free(s->dsz), free(s->dw);
    memset(s, 0, sizeof *s);
}

/* Layer 1 for every (shape, sample): s1 = s_z + u·W1[:,0] + v·W1[:,1], then
 * a1 = softplus(s1) and, with tangents, a1_u = σ(s1)·W1[:,0], a1_v likewise. */
static void layer1_forward(const tcb_atlas_decoder_cache *c, const float *uv, int nt, int h1)
{
    int m = c->m, R = c->nz * m;
    size_t blk = (size_t)R * h1;
    const float *wu = c->wuv, *wv = c->wuv + h1;
#pragma omp parallel for schedule(static) if ((double)R * h1 > TCB_PAR_MIN)
    for (int r = 0; r < R; r++) {
        const float *sz = c->sz + (size_t)(r / m) * h1;
        float u = uv[2 * (r % m)], v = uv[2 * (r % m) + 1];
        float *s1 = c->s1 + (size_t)r * h1, *a = c->a1 + (size_t)r * h1;
        float *au = a + blk, *av = a + 2 * blk;
        if (nt) {
#pragma omp simd
            for (int j = 0; j < h1; j++) {
                float sig, s = sz[j] + u * wu[j] + v * wv[j];
                s1[j] = s;
                a[j] = tcb_softplus(s, &sig);
                au[j] = sig * wu[j];
                av[j] = sig * wv[j];
            }
        } else {
#pragma omp simd
            for (int j = 0; j < h1; j++) {
                float sig, s = sz[j] + u * wu[j] + v * wv[j];
                s1[j] = s;
                a[j] = tcb_softplus(s, &sig);
            }
        }
    }
}

void tcb_atlas_decoder_forward(const tcb_atlas_decoder *d, tcb_atlas_decoder_cache *c,
                               const float *z, const float *uv, int nt, float *out)
{
    int C = c->C, h1 = C + 2, h2 = h1 / 2, h3 = h1 / 4, R = c->nz * c->m;
    const float *W1 = d->l[0].W;
    c->nt = nt;
    for (int j = 0; j < h1; j++) {
        c->wuv[j] = W1[(size_t)j * h1];
        c->wuv[h1 + j] = W1[(size_t)j * h1 + 1];
    }
    /* s_z [nz][H1] = z · W1[:, 2:]ᵀ + b1, once per (shape, patch); W1's z
     * block is a submatrix with leading dimension C + 2 */
    for (int b = 0; b < c->nz; b++) memcpy(c->sz + (size_t)b * h1, d->l[0].b, h1 * sizeof(float));
    cblas_sgemm(CblasRowMajor, CblasNoTrans, CblasTrans, c->nz, h1, C, 1.0f, z, C, W1 + 2, h1,
                1.0f, c->sz, h1);
    layer1_forward(c, uv, nt, h1);
    tcb_linear_forward(c->x2, c->a1, d->l[1].W, d->l[1].b, R, nt, h1, h2);
    tcb_softplus_forward(c->a2, c->x2, R, nt, h2);
    tcb_linear_forward(c->x3, c->a2, d->l[2].W, d->l[2].b, R, nt, h2, h3);
    tcb_softplus_forward(c->a3, c->x3, R, nt, h3);
    tcb_linear_forward(out, c->a3, d->l[3].W, d->l[3].b, R, nt, h3, 3);
}

/* Layer 1 backward, given da = ∂L/∂[a1; a1_u; a1_v] (stacked): per element
 *     ds = σ·da + σ(1−σ)·(W1[:,0]·da_u + W1[:,1]·da_v),
 * and ∂L/∂W1[:,0] gathers Σ (σ·da_u + ds·u) over the rows (the tangent IS
 * that column), ∂L/∂W1[:,1] likewise. dx receives ds and those two per-row
 * terms; the column sums follow. */
static void layer1_backward_rows(const tcb_atlas_decoder_cache *c, const float *uv,
                                 const float *da, float *dx, int nt, int h1)
{
    int m = c->m, R = c->nz * m;
    size_t blk = (size_t)R * h1;
    const float *wu = c->wuv, *wv = c->wuv + h1;
#pragma omp parallel for schedule(static) if ((double)R * h1 > TCB_PAR_MIN)
    for (int r = 0; r < R; r++) {
        float u = uv[2 * (r % m)], v = uv[2 * (r % m) + 1];
        const float *s1 = c->s1 + (size_t)r * h1, *g = da + (size_t)r * h1;
        const float *gu = g + blk, *gv = g + 2 * blk; /* read only if nt */
        float *ds = dx + (size_t)r * h1, *pu = ds + blk, *pv = ds + 2 * blk;
        if (nt) {
#pragma omp simd
            for (int j = 0; j < h1; j++) {
                float curv, sig = tcb_sigmoid(s1[j], &curv);
                float d = sig * g[j] + curv * (wu[j] * gu[j] + wv[j] * gv[j]);
                ds[j] = d;
                pu[j] = sig * gu[j] + d * u;
                pv[j] = sig * gv[j] + d * v;
            }
        } else {
#pragma omp simd
            for (int j = 0; j < h1; j++) {
                float curv, d = tcb_sigmoid(s1[j], &curv) * g[j];
                ds[j] = d;
                pu[j] = d * u;
                pv[j] = d * v;
            }
        }
    }
}

static void layer1_backward(const tcb_atlas_decoder *d, const tcb_atlas_decoder *grad,
                            const tcb_atlas_decoder_cache *c, tcb_atlas_decoder_scratch *s,
                            const float *z, const float *uv, int nt, float *dz, float *duv)
{
    int C = c->C, h1 = C + 2, m = c->m, nz = c->nz, R = nz * m;
    size_t blk = (size_t)R * h1;
    const float *W1 = d->l[0].W;
    float *gW1 = grad->l[0].W;
    layer1_backward_rows(c, uv, s->da, s->dx, nt, h1);
    /* the uv columns of W1 */
    memset(s->dw, 0, 2 * (size_t)h1 * sizeof(float));
    tcb_colsum_acc(s->dw, s->dx + blk, R, h1);
    tcb_colsum_acc(s->dw + h1, s->dx + 2 * blk, R, h1);
    for (int j = 0; j < h1; j++) {
        gW1[(size_t)j * h1] += s->dw[j];
        gW1[(size_t)j * h1 + 1] += s->dw[h1 + j];
    }
    /* the z part: ds_z = Σ over each shape's samples of ds */
    memset(s->dsz, 0, (size_t)nz * h1 * sizeof(float));
    for (int b = 0; b < nz; b++)
        tcb_colsum_acc(s->dsz + (size_t)b * h1, s->dx + (size_t)b * m * h1, m, h1);
    tcb_colsum_acc(grad->l[0].b, s->dsz, nz, h1);
    cblas_sgemm(CblasRowMajor, CblasTrans, CblasNoTrans, h1, C, nz, 1.0f, s->dsz, h1, z, C, 1.0f,
                gW1 + 2, h1);
    cblas_sgemm(CblasRowMajor, CblasNoTrans, CblasNoTrans, nz, C, h1, 1.0f, s->dsz, h1, W1 + 2,
                h1, 1.0f, dz, C);
    if (!duv) return;
    /* ∂s1/∂u = W1[:,0]; shapes share the samples, so their terms add up */
    for (int r = 0; r < R; r++) {
        const float *ds = s->dx + (size_t)r * h1;
        double du = 0.0, dv = 0.0;
        for (int j = 0; j < h1; j++) {
            du += (double)ds[j] * c->wuv[j];
            dv += (double)ds[j] * c->wuv[h1 + j];
        }
        duv[2 * (r % m)] += (float)du;
        duv[2 * (r % m) + 1] += (float)dv;
    }
}

void tcb_atlas_decoder_backward(const tcb_atlas_decoder *d, const tcb_atlas_decoder *grad,
                                const tcb_atlas_decoder_cache *c,
                                tcb_atlas_decoder_scratch *s, const float *z, const float *uv,
                                const float *dout, int nt, float *dz, float *duv)
{
    int C = c->C, h1 = C + 2, h2 = h1 / 2, h3 = h1 / 4, R = c->nz * c->m;
    const tcb_linear *l = d->l, *g = grad->l;
    tcb_linear_backward(s->da, g[3].W, g[3].b, dout, c->a3, l[3].W, R, nt, h3, 3);
    tcb_softplus_backward(s->dx, s->da, c->x3, R, nt, h3);
    tcb_linear_backward(s->da, g[2].W, g[2].b, s->dx, c->a2, l[2].W, R, nt, h2, h3);
    tcb_softplus_backward(s->dx, s->da, c->x2, R, nt, h2);
    tcb_linear_backward(s->da, g[1].W, g[1].b, s->dx, c->a1, l[1].W, R, nt, h1, h2);
    layer1_backward(d, grad, c, s, z, uv, nt, dz, duv);
}
