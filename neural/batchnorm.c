#include "neural/batchnorm.h"

#include <stdint.h>

#include <math.h>

#include "neural/layers.h"
#include "neural/parallel.h"

/* Row blocks of a reduction: a fixed partition, summed each in order and
 * then added in block order, so results do not depend on the thread count
 * (up to NB threads share the work). Rows are walked whole: tasks of a few
 * columns stride across rows and miss the caches and the TLB (16-column
 * tasks over 256 columns: 8× slower, measured). */
#define NB 4

/* s1 = Σ_r u and s2 = Σ_r u·v per column over the n rows, with u = a − sa
 * and v = b − sb (sa, sb [C]), summed in double. One pass serves both the
 * forward's moments (a = b = x, shifted by a sample row) and the
 * backward's column sums (a = dy, b = x̂, no shift). */
static void moments(const float *a, const float *b, const float *sa, const float *sb, int n, int C, double *s1,
                    double *s2)
{
    double part[NB][2][TCB_BN_MAX_C];
#pragma omp parallel for schedule(static) if ((double)n * C > TCB_PAR_MIN)
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

/* The batch statistics of x [n][C]: rstd, mu, var2 as forward_train
 * keeps them, and mlo, the mean's low float part (μ = mu + mlo), which x̂
 * needs. */
static void batch_stats(const float *x, int n, int C, float *rstd, float *mu, float *mlo, float *var2)
{
    /* the moments about the first row in one pass: Σu and Σu² of u = x − x_0
     * give σ² = Σu²/n − (Σu/n)² without the cancellation of Σx² − n·μ² when
     * |μ| ≫ σ (a batch norm after a layer with a large bias), since x_0 lies
     * within a few σ of μ */
    double s1[TCB_BN_MAX_C], s2[TCB_BN_MAX_C];
    moments(x, x, x, x, n, C, s1, s2);
    for (int j = 0; j < C; j++) {
        double d = s1[j] / n, m = x[j] + d, v = s2[j] / n - d * d;
        if (v < 0) v = 0;
        mu[j] = (float)m, var2[j] = (float)v, rstd[j] = (float)(1.0 / sqrt(v + TCB_BN_EPS));
        mlo[j] = (float)(m - mu[j]);
    }
}

/* x̂ = (x − μ)·rstd with the subtraction first and μ as the float pair mu +
 * mlo: x·rstd − μ·rstd would cancel the same way (an error of ~1e-7·|μ|/σ
 * in x̂). Every path computes x̂ with this one expression, so a fused layer
 * that recomputes x̂ gets the bits the unfused one stored. */
static inline float hat(float x, float mu, float mlo, float rstd) { return ((x - mu) - mlo) * rstd; }

void tcb_batchnorm_forward_train(const tcb_batchnorm *bn, float *y, float *xhat, float *rstd, float *mu,
                                 float *var2, const float *x, int n, int relu)
{
    int C = bn->C;
    float mlo[TCB_BN_MAX_C];
    batch_stats(x, n, C, rstd, mu, mlo, var2);
    const float *g = bn->gamma, *b = bn->beta;
#pragma omp parallel for schedule(static) if ((double)n * C > TCB_PAR_MIN)
    for (int r = 0; r < n; r++) {
        size_t at = (size_t)r * C;
#pragma omp simd
        for (int j = 0; j < C; j++) {
            float h = hat(x[at + j], mu[j], mlo[j], rstd[j]), o = g[j] * h + b[j];
            xhat[at + j] = h;
            y[at + j] = relu && !(o > 0.0f) ? 0.0f : o;
        }
    }
}

void tcb_batchnorm_maxpool_forward_train(const tcb_batchnorm *bn, float *g, int32_t *arg, float *rstd, float *mu,
                                         float *mlo, float *var2, const float *x, int nb, int n)
{
    int C = bn->C;
    batch_stats(x, nb * n, C, rstd, mu, mlo, var2);
    const float *ga = bn->gamma, *be = bn->beta;
    /* each set's rows through BN one at a time into a row buffer, and the
     * max taken as tcb_maxpool_forward takes it (the first row of the
     * largest value) */
#pragma omp parallel for schedule(static) if ((double)nb * n * C > TCB_PAR_MIN)
    for (int b = 0; b < nb; b++) {
        float y[TCB_BN_MAX_C];
        float *gb = g + (size_t)b * C;
        int32_t *ab = arg + (size_t)b * C;
        for (int i = 0; i < n; i++) {
            const float *xr = x + ((size_t)b * n + i) * C;
#pragma omp simd
            for (int j = 0; j < C; j++) y[j] = ga[j] * hat(xr[j], mu[j], mlo[j], rstd[j]) + be[j];
            for (int j = 0; j < C; j++)
                if (i == 0 || y[j] > gb[j]) gb[j] = y[j], ab[j] = i;
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
#pragma omp parallel for schedule(static) if ((double)n * C > TCB_PAR_MIN)
    for (int r = 0; r < n; r++) {
        size_t at = (size_t)r * C;
#pragma omp simd
        for (int j = 0; j < C; j++) {
            float o = (x[at + j] - m[j]) * sc[j] + b[j];
            y[at + j] = relu && !(o > 0.0f) ? 0.0f : o;
        }
    }
}

/* From the column sums sd = Σdy and sdx = Σdy·x̂ over n rows: dβ and dγ
 * accumulated, and dx's coefficients a = γ·rstd, mb = sd/n, mg = sdx/n. */
static void backward_coefficients(const tcb_batchnorm *bn, const tcb_batchnorm *grad, const float *rstd,
                                  const double *sd, const double *sdx, int n, float *a, float *mb, float *mg)
{
    for (int j = 0; j < bn->C; j++) {
        grad->beta[j] += (float)sd[j];
        grad->gamma[j] += (float)sdx[j];
        a[j] = bn->gamma[j] * rstd[j];
        mb[j] = (float)(sd[j] / n), mg[j] = (float)(sdx[j] / n);
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
    backward_coefficients(bn, grad, rstd, sd, sdx, n, a, mb, mg);
#pragma omp parallel for schedule(static) if ((double)n * C > TCB_PAR_MIN)
    for (int r = 0; r < n; r++) {
        size_t at = (size_t)r * C;
#pragma omp simd
        for (int j = 0; j < C; j++) dx[at + j] = a[j] * (dy[at + j] - mb[j] - xhat[at + j] * mg[j]);
    }
}

/* The column sums of dy and dy·x̂ for a dy that is zero but at each set's
 * max rows, in moments()'s order: its row blocks, each summed in row
 * order (the sets' rows ascend with the set), the blocks added in order,
 * so the sums equal those over the dense dy bit for bit. */
static void sparse_moments(const float *dg, const int32_t *arg, const float *x, const float *rstd, const float *mu,
                           const float *mlo, int nb, int n, int C, double *sd, double *sdx)
{
    int R = nb * n;
    for (int j = 0; j < C; j++) {
        sd[j] = sdx[j] = 0;
        for (int k = 0, b = 0; k < NB; k++) {
            int r1 = (int)((long long)R * (k + 1) / NB);
            double p1 = 0, p2 = 0;
            for (; b < nb; b++) {
                int r = b * n + arg[(size_t)b * C + j];
                if (r >= r1) break;
                double u = dg[(size_t)b * C + j], v = hat(x[(size_t)r * C + j], mu[j], mlo[j], rstd[j]);
                p1 += u, p2 += u * v;
            }
            if (k == 0) sd[j] = p1, sdx[j] = p2;
            else sd[j] += p1, sdx[j] += p2;
        }
    }
}

void tcb_batchnorm_maxpool_backward(const tcb_batchnorm *bn, const tcb_batchnorm *grad, float *dx, const float *dg,
                                    const int32_t *arg, const float *x, const float *rstd, const float *mu,
                                    const float *mlo, int nb, int n)
{
    int C = bn->C, R = nb * n;
    double sd[TCB_BN_MAX_C], sdx[TCB_BN_MAX_C];
    sparse_moments(dg, arg, x, rstd, mu, mlo, nb, n, C, sd, sdx);
    float a[TCB_BN_MAX_C], mb[TCB_BN_MAX_C], mg[TCB_BN_MAX_C];
    backward_coefficients(bn, grad, rstd, sd, sdx, R, a, mb, mg);
    /* tcb_batchnorm_backward's dx with dy = 0 everywhere, then the max rows
     * with their dy */
#pragma omp parallel for schedule(static) if ((double)R * C > TCB_PAR_MIN)
    for (int r = 0; r < R; r++) {
        size_t at = (size_t)r * C;
#pragma omp simd
        for (int j = 0; j < C; j++) dx[at + j] = a[j] * (0.0f - mb[j] - hat(x[at + j], mu[j], mlo[j], rstd[j]) * mg[j]);
    }
    for (int b = 0; b < nb; b++)
        for (int j = 0; j < C; j++) {
            size_t at = ((size_t)b * n + arg[(size_t)b * C + j]) * C + j;
            dx[at] = a[j] * (dg[(size_t)b * C + j] - mb[j] - hat(x[at], mu[j], mlo[j], rstd[j]) * mg[j]);
        }
}
