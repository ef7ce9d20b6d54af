#include "neural/batchnorm.h"

#include <stdint.h>

#include <math.h>

#include "neural/layers.h"

/* Row blocks of a reduction: a fixed partition, summed each in order and
 * then added in block order, so results do not depend on the thread count
 * (up to NB threads share the work). Rows are walked whole: tasks of a few
 * columns stride across rows and miss the caches and the TLB (16-column
 * tasks over 256 columns: 8× slower, measured). */
#define NB 4

/* Below this many elements a thread team costs more than it saves. */
#define PAR_MIN 32768.0

/* s1 = Σ_r u and s2 = Σ_r u·v per column over the n rows, with u = a − sa
 * and v = b − sb (sa, sb [C]), summed in double. One pass serves both the
 * forward's moments (a = b = x, shifted by a sample row) and the
 * backward's column sums (a = dy, b = x̂, no shift). */
static void moments(const float *a, const float *b, const float *sa, const float *sb, int n, int C, double *s1,
                    double *s2)
{
    double part[NB][2][TCB_BN_MAX_C];
#pragma omp parallel for schedule(static) if ((double)n * C > PAR_MIN)
    for (int k = 0; k < NB; k++) {
        int r0 = (int)((long long)n * k / NB), r1 = (int)((long long)n * (k + 1) / NB);
        double *p1 = part[k][0], *p2 = part[k][1];
        for (int j = 0; j < C; j++) p1[j] = p2[j] = 0;
        for (int r = r0; r < r1; r++) {
            const float *ar = a + (size_t)r * C, *br = b + (size_t)r * C;
#pragma omp simd
            for (int j = 0; j < C; j++) {
                double u = ar[j] - sa[j], v = br[j] - sb[j];
                p1[j] += u, p2[j] += u * v;
            }
        }
    }
    for (int j = 0; j < C; j++) {
        s1[j] = part[0][0][j], s2[j] = part[0][1][j];
        for (int k = 1; k < NB; k++) s1[j] += part[k][0][j], s2[j] += part[k][1][j];
    }
}

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
                                 float *var2, const float *x, int n, int relu)
{
    int C = bn->C;
    /* the moments about the first row in one pass: Σu and Σu² of u = x − x_0
     * give σ² = Σu²/n − (Σu/n)² without the cancellation of Σx² − n·μ² when
     * |μ| ≫ σ (a batch norm after a layer with a large bias), since x_0 lies
     * within a few σ of μ */
    double s1[TCB_BN_MAX_C], s2[TCB_BN_MAX_C];
    moments(x, x, x, x, n, C, s1, s2);
    /* x̂ = (x − μ)·rstd with the subtraction first and μ as a float pair
     * hi + lo: x·rstd − μ·rstd would cancel the same way (an error of
     * ~1e-7·|μ|/σ in x̂) */
    float sc[TCB_BN_MAX_C], mhi[TCB_BN_MAX_C], mlo[TCB_BN_MAX_C];
    for (int j = 0; j < C; j++) {
        double d = s1[j] / n, m = x[j] + d, v = s2[j] / n - d * d;
        if (v < 0) v = 0;
        double rs = 1.0 / sqrt(v + TCB_BN_EPS);
        mu[j] = (float)m, var2[j] = (float)v, rstd[j] = (float)rs;
        sc[j] = (float)rs, mhi[j] = (float)m, mlo[j] = (float)(m - mhi[j]);
    }
    const float *g = bn->gamma, *b = bn->beta;
#pragma omp parallel for schedule(static) if ((double)n * C > PAR_MIN)
    for (int r = 0; r < n; r++) {
        size_t at = (size_t)r * C;
#pragma omp simd
        for (int j = 0; j < C; j++) {
            float h = ((x[at + j] - mhi[j]) - mlo[j]) * sc[j], o = g[j] * h + b[j];
            xhat[at + j] = h;
            y[at + j] = relu && !(o > 0.0f) ? 0.0f : o;
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

void tcb_batchnorm_forward_eval(const tcb_batchnorm *bn, float *y, const float *x, int n, int relu)
{
    /* y = (x − r_μ)·γ/√(r_σ² + eps) + β, subtracting first (as the training
     * forward): x·sc + (β − r_μ·sc) cancels when |r_μ| ≫ r_σ */
    int C = bn->C;
    float sc[TCB_BN_MAX_C];
    for (int j = 0; j < C; j++) sc[j] = (float)(bn->gamma[j] / sqrt((double)bn->var[j] + TCB_BN_EPS));
    const float *m = bn->mean, *b = bn->beta;
#pragma omp parallel for schedule(static) if ((double)n * C > PAR_MIN)
    for (int r = 0; r < n; r++) {
        size_t at = (size_t)r * C;
#pragma omp simd
        for (int j = 0; j < C; j++) {
            float o = (x[at + j] - m[j]) * sc[j] + b[j];
            y[at + j] = relu && !(o > 0.0f) ? 0.0f : o;
        }
    }
}

void tcb_batchnorm_backward(const tcb_batchnorm *bn, const tcb_batchnorm *grad, float *dx, const float *dy,
                            const float *y, const float *xhat, const float *rstd, int n)
{
    static const float zero[TCB_BN_MAX_C];
    int C = bn->C;
    if (y) { /* through the fused ReLU first: dx is then the masked dy */
        tcb_relu_backward(dx, dy, y, (int64_t)n * C);
        dy = dx;
    }
    double sd[TCB_BN_MAX_C], sdx[TCB_BN_MAX_C];
    moments(dy, xhat, zero, zero, n, C, sd, sdx);
    float a[TCB_BN_MAX_C], mb[TCB_BN_MAX_C], mg[TCB_BN_MAX_C];
    for (int j = 0; j < C; j++) {
        grad->beta[j] += (float)sd[j];
        grad->gamma[j] += (float)sdx[j];
        a[j] = bn->gamma[j] * rstd[j];
        mb[j] = (float)(sd[j] / n), mg[j] = (float)(sdx[j] / n);
    }
#pragma omp parallel for schedule(static) if ((double)n * C > PAR_MIN)
    for (int r = 0; r < n; r++) {
        size_t at = (size_t)r * C;
#pragma omp simd
        for (int j = 0; j < C; j++) dx[at + j] = a[j] * (dy[at + j] - mb[j] - xhat[at + j] * mg[j]);
    }
}
