#include "neural/batchnorm.h"

#include <math.h>

/* Column chunk of the reductions: one thread owns a chunk and sums its
 * columns over the rows in order, whatever the thread count. */
#define CHUNK 64

/* Below this many elements a thread team costs more than it saves. */
#define PAR_MIN 32768.0

static int imin(int a, int b) { return a < b ? a : b; }

void tcb_batchnorm_bind(tcb_batchnorm *bn, float *params, size_t *poff, float *buffers, size_t *boff, int C)
{
    bn->gamma = params + *poff;
    bn->beta = bn->gamma + C;
    *poff += 2 * (size_t)C;
    bn->mean = bn->var = NULL;
    if (buffers) {
        bn->mean = buffers + *boff;
        bn->var = bn->mean + C;
        *boff += 2 * (size_t)C;
    }
    bn->C = C;
}

void tcb_batchnorm_reset_running(const tcb_batchnorm *bn)
{
    for (int c = 0; c < bn->C; c++) bn->mean[c] = 0.0f, bn->var[c] = 1.0f;
}

void tcb_batchnorm_forward_train(const tcb_batchnorm *bn, float *y, float *xhat, float *rstd, float *mu,
                                 float *var2, const float *x, int n)
{
    int C = bn->C, nchunks = (C + CHUNK - 1) / CHUNK;
#pragma omp parallel for schedule(static) if ((double)n * C > PAR_MIN)
    for (int k = 0; k < nchunks; k++) {
        int lo = k * CHUNK, w = imin(C, lo + CHUNK) - lo;
        double s[CHUNK] = {0}, ss[CHUNK] = {0};
        for (int r = 0; r < n; r++) {
            const float *row = x + (size_t)r * C + lo;
            for (int j = 0; j < w; j++) s[j] += row[j];
        }
        /* the variance about the mean in a second pass: Σx² − n·μ² cancels
         * badly when |μ| ≫ σ (a BN after a layer with a large bias) */
        for (int j = 0; j < w; j++) s[j] /= n;
        for (int r = 0; r < n; r++) {
            const float *row = x + (size_t)r * C + lo;
            for (int j = 0; j < w; j++) {
                double d = row[j] - s[j];
                ss[j] += d * d;
            }
        }
        /* x̂ = (x − μ)·rstd with the subtraction first and μ as a float pair
         * hi + lo: x·rstd − μ·rstd would cancel the same way (an error of
         * ~1e-7·|μ|/σ in x̂) */
        float sc[CHUNK], mhi[CHUNK], mlo[CHUNK];
        for (int j = 0; j < w; j++) {
            double v = ss[j] / n, rs = 1.0 / sqrt(v + TCB_BN_EPS);
            mu[lo + j] = (float)s[j], var2[lo + j] = (float)v, rstd[lo + j] = (float)rs;
            sc[j] = (float)rs, mhi[j] = (float)s[j], mlo[j] = (float)(s[j] - mhi[j]);
        }
        const float *g = bn->gamma + lo, *b = bn->beta + lo;
        for (int r = 0; r < n; r++) {
            size_t at = (size_t)r * C + lo;
            for (int j = 0; j < w; j++) {
                float h = ((x[at + j] - mhi[j]) - mlo[j]) * sc[j];
                xhat[at + j] = h;
                y[at + j] = g[j] * h + b[j];
            }
        }
    }
}

void tcb_batchnorm_update_running(const tcb_batchnorm *bn, const float *mu, const float *var2, int n)
{
    /* as PyTorch: the scalars in double, the unbiased variance n/(n−1) */
    double m = TCB_BN_MOMENTUM, unbias = n > 1 ? (double)n / (n - 1) : 1.0;
    for (int c = 0; c < bn->C; c++) {
        bn->mean[c] = (float)(m * mu[c] + (1.0 - m) * bn->mean[c]);
        bn->var[c] = (float)(m * var2[c] * unbias + (1.0 - m) * bn->var[c]);
    }
}

void tcb_batchnorm_forward_eval(const tcb_batchnorm *bn, float *y, const float *x, int n)
{
    int C = bn->C, nchunks = (C + CHUNK - 1) / CHUNK;
#pragma omp parallel for schedule(static) if ((double)n * C > PAR_MIN)
    for (int k = 0; k < nchunks; k++) {
        int lo = k * CHUNK, w = imin(C, lo + CHUNK) - lo;
        /* y = (x − r_μ)·γ/√(r_σ² + eps) + β, subtracting first (as the
         * training forward): x·sc + (β − r_μ·sc) cancels when |r_μ| ≫ r_σ */
        float sc[CHUNK], m[CHUNK];
        const float *b = bn->beta + lo;
        for (int j = 0; j < w; j++) {
            double rs = 1.0 / sqrt((double)bn->var[lo + j] + TCB_BN_EPS);
            sc[j] = (float)(bn->gamma[lo + j] * rs), m[j] = bn->mean[lo + j];
        }
        for (int r = 0; r < n; r++) {
            size_t at = (size_t)r * C + lo;
            for (int j = 0; j < w; j++) y[at + j] = (x[at + j] - m[j]) * sc[j] + b[j];
        }
    }
}

void tcb_batchnorm_backward(const tcb_batchnorm *bn, const tcb_batchnorm *grad, float *dx, const float *dy,
                            const float *xhat, const float *rstd, int n)
{
    int C = bn->C, nchunks = (C + CHUNK - 1) / CHUNK;
#pragma omp parallel for schedule(static) if ((double)n * C > PAR_MIN)
    for (int k = 0; k < nchunks; k++) {
        int lo = k * CHUNK, w = imin(C, lo + CHUNK) - lo;
        double sd[CHUNK] = {0}, sdx[CHUNK] = {0};
        for (int r = 0; r < n; r++) {
            size_t at = (size_t)r * C + lo;
            for (int j = 0; j < w; j++) sd[j] += dy[at + j], sdx[j] += (double)dy[at + j] * xhat[at + j];
        }
        float a[CHUNK], mb[CHUNK], mg[CHUNK];
        for (int j = 0; j < w; j++) {
            grad->beta[lo + j] += (float)sd[j];
            grad->gamma[lo + j] += (float)sdx[j];
            a[j] = bn->gamma[lo + j] * rstd[lo + j];
            mb[j] = (float)(sd[j] / n), mg[j] = (float)(sdx[j] / n);
        }
        for (int r = 0; r < n; r++) {
            size_t at = (size_t)r * C + lo;
            for (int j = 0; j < w; j++) dx[at + j] = a[j] * (dy[at + j] - mb[j] - xhat[at + j] * mg[j]);
        }
    }
}
