#include "neural/layers.h"

#include <cblas.h>
#include <math.h>
#include <omp.h>
#include <stddef.h>
#include <string.h>

#include "neural/parallel.h"
#include "tcb/rng.h"

/* Dimensions up to this are "tiny": a GEMM with a 3-wide side spends its
 * time in packing and dispatch, a fused loop streams the other operand once. */
#define TINY 3

/* Column chunk of the reductions over rows: one thread owns a chunk, so each
 * sum runs over the rows in order whatever the thread count. */
#define CHUNK 64

/* Below this many multiply-adds (tens of microseconds) a product is left
 * to one OpenBLAS call, which threads it or not by its own measure: a team
 * of blocks would save less than it costs to start. */
#define SPLIT_MIN 1048576.0

static int imin(int a, int b) { return a < b ? a : b; }

/* C [rows][n] = A [rows][k] · op(B) + beta·C, row-major (op(B) = Bᵀ with B
 * [n][k] when b_trans, else B [k][n]), the rows cut into one even block per
 * OpenMP thread, each block a single-threaded OpenBLAS call (the OpenMP
 * build runs a call made inside a parallel region on its caller's thread).
 * Why not OpenBLAS's own threads: on the layers' tall narrow products
 * (rows ≫ n, k ≤ 128) they wait on one another's packed panels; at two
 * threads this split ran cc's 64-wide layers 1.6–1.75× faster forward
 * and 1.1–1.2× backward, dynosurf's 128-wide ones 1.1×, the 512- and
 * 1 024-wide ones as fast
 * (bench/linear.c; docs/protocol.md, "Row-split products").
 * The blocks depend on the thread count only, so a given count gives the
 * same bits every run; one thread is the one call as before. (OpenBLAS's
 * edge tiles round otherwise than its full ones, so the bits of a row
 * depend on where its block starts: no split is the same at every count.) */
static void sgemm_rows(int b_trans, int rows, int n, int k, const float *A, const float *B, float beta,
                       float *C)
{
    int ldb = b_trans ? k : n;
#pragma omp parallel if ((double)rows * n * k > SPLIT_MIN)
    {
        int t = omp_get_thread_num(), T = omp_get_num_threads();
        int r0 = (int)((long long)rows * t / T), r1 = (int)((long long)rows * (t + 1) / T);
        if (r1 > r0)
            cblas_sgemm(CblasRowMajor, CblasNoTrans, b_trans ? CblasTrans : CblasNoTrans, r1 - r0, n, k, 1.0f,
                        A + (size_t)r0 * k, k, B, ldb, beta, C + (size_t)r0 * n, n);
    }
}

void tcb_linear_bind(tcb_linear *l, float *base, size_t *offset, int in, int out)
{
    l->W = base + *offset;
    l->b = l->W + (size_t)in * out;
    l->in = in, l->out = out;
    *offset += (size_t)in * out + out;
}

void tcb_linear_bind_nobias(tcb_linear *l, float *base, size_t *offset, int in, int out)
{
    l->W = base + *offset;
    l->b = NULL;
    l->in = in, l->out = out;
    *offset += (size_t)in * out;
}

void tcb_colsum_acc(float *db, const float *dy, int n, int d)
{
    int nchunks = (d + CHUNK - 1) / CHUNK;
#pragma omp parallel for schedule(static) if ((double)n * d > TCB_PAR_MIN)
    for (int c = 0; c < nchunks; c++) {
        int lo = c * CHUNK, w = imin(d, lo + CHUNK) - lo;
        double acc[CHUNK] = {0};
        for (int r = 0; r < n; r++) {
            const float *row = dy + (size_t)r * d + lo;
            for (int j = 0; j < w; j++) acc[j] += row[j];
        }
        for (int j = 0; j < w; j++) db[lo + j] += (float)acc[j];
    }
}

/* y[rows][d] = b on the first n rows, 0 on the rest (b NULL: 0 everywhere). */
static void fill_bias(float *y, const float *b, int n, int rows, int d)
{
#pragma omp parallel for schedule(static) if ((double)rows * d > TCB_PAR_MIN)
    for (int r = 0; r < rows; r++) {
        float *yr = y + (size_t)r * d;
        if (b && r < n) memcpy(yr, b, (size_t)d * sizeof(float));
        else memset(yr, 0, (size_t)d * sizeof(float));
    }
}

/* y[rows][out] += x[rows][in]·Wᵀ for a tiny in: W's columns are copied to
 * contiguous rows first, so the inner loop runs over outputs. */
static void tiny_in_forward(float *y, const float *x, const float *W, int rows, int in, int out)
{
    for (int lo = 0; lo < out; lo += CHUNK) {
        int w = imin(out - lo, CHUNK);
        float wt[TINY][CHUNK];
        for (int k = 0; k < in; k++)
            for (int j = 0; j < w; j++) wt[k][j] = W[(size_t)(lo + j) * in + k];
#pragma omp parallel for schedule(static) if ((double)rows * in * w > TCB_PAR_MIN)
        for (int r = 0; r < rows; r++) {
            float *yr = y + (size_t)r * out + lo;
            for (int k = 0; k < in; k++) {
                float xk = x[(size_t)r * in + k];
#pragma omp simd
                for (int j = 0; j < w; j++) yr[j] += xk * wt[k][j];
            }
        }
    }
}

/* y[rows][out] += x[rows][in]·Wᵀ for a tiny out: a dot product per output. */
static void tiny_out_forward(float *y, const float *x, const float *W, int rows, int in, int out)
{
#pragma omp parallel for schedule(static) if ((double)rows * in * out > TCB_PAR_MIN)
    for (int r = 0; r < rows; r++) {
        const float *xr = x + (size_t)r * in;
        float *yr = y + (size_t)r * out;
        for (int o = 0; o < out; o++) {
            const float *w = W + (size_t)o * in;
            float acc = 0.0f;
#pragma omp simd reduction(+ : acc)
            for (int k = 0; k < in; k++) acc += xr[k] * w[k];
            yr[o] += acc;
        }
    }
}

/* dx[rows][in] = dy[rows][out]·W for a tiny in or out. */
static void tiny_backward_input(float *dx, const float *dy, const float *W, int rows, int in,
                                int out)
{
#pragma omp parallel for schedule(static) if ((double)rows * in * out > TCB_PAR_MIN)
    for (int r = 0; r < rows; r++) {
        const float *g = dy + (size_t)r * out;
        float *dxr = dx + (size_t)r * in;
        for (int k = 0; k < in; k++) dxr[k] = 0.0f;
        for (int o = 0; o < out; o++) {
            const float *w = W + (size_t)o * in;
            for (int k = 0; k < in; k++) dxr[k] += g[o] * w[k];
        }
    }
}

/* dW[out][in] += Σ_r dy[r][o]·x[r][k] for a tiny in or out: threads own
 * chunks of the large side and sum the rows in order, in double. */
static void tiny_backward_weight(float *dW, const float *dy, const float *x, int rows, int in,
                                 int out)
{
    int in_big = in >= out, big = in_big ? in : out, small = in_big ? out : in;
    int nchunks = (big + CHUNK - 1) / CHUNK;
#pragma omp parallel for schedule(static) if ((double)rows * in * out > TCB_PAR_MIN)
    for (int c = 0; c < nchunks; c++) {
        int lo = c * CHUNK, w = imin(big, lo + CHUNK) - lo;
        double acc[TINY][CHUNK] = {{0}};
        for (int r = 0; r < rows; r++) {
            const float *g = dy + (size_t)r * out, *xr = x + (size_t)r * in;
            for (int s = 0; s < small; s++) {
                /* in_big: acc[o][k] over k in the chunk; else acc[k][o] over o */
                double a = in_big ? g[s] : xr[s];
                const float *v = in_big ? xr + lo : g + lo;
                for (int j = 0; j < w; j++) acc[s][j] += a * v[j];
            }
        }
        for (int s = 0; s < small; s++)
            for (int j = 0; j < w; j++) {
                size_t at = in_big ? (size_t)s * in + lo + j : (size_t)(lo + j) * in + s;
                dW[at] += (float)acc[s][j];
            }
    }
}

void tcb_linear_forward(float *y, const float *x, const float *W, const float *b, int n,
                              int nt, int in, int out)
{
    int rows = (1 + nt) * n;
    /* the bias goes in first and the product is added (beta = 1): one pass
     * over y, where beta = 0 and a bias pass would be two */
    fill_bias(y, b, n, rows, out);
    if (in <= TINY)
        tiny_in_forward(y, x, W, rows, in, out);
    else if (out <= TINY)
        tiny_out_forward(y, x, W, rows, in, out);
    else
        sgemm_rows(1, rows, out, in, x, W, 1.0f, y);
}

void tcb_linear_backward(float *dx, float *dW, float *db, const float *dy, const float *x,
                               const float *W, int n, int nt, int in, int out)
{
    int rows = (1 + nt) * n;
    if (db) tcb_colsum_acc(db, dy, n, out);
    if (in <= TINY || out <= TINY) {
        tiny_backward_weight(dW, dy, x, rows, in, out);
        if (dx) tiny_backward_input(dx, dy, W, rows, in, out);
        return;
    }
    cblas_sgemm(CblasRowMajor, CblasTrans, CblasNoTrans, out, in, rows, 1.0f, dy, out, x, in,
                1.0f, dW, in);
    if (dx) sgemm_rows(0, rows, in, out, dy, W, 0.0f, dx);
}

void tcb_relu_forward(float *y, const float *x, int64_t n)
{
#pragma omp parallel for schedule(static) if ((double)n > TCB_PAR_MIN)
    for (int64_t i = 0; i < n; i++) y[i] = x[i] > 0.0f ? x[i] : 0.0f;
}

void tcb_relu_backward(float *dx, const float *dy, const float *y, int64_t n)
{
#pragma omp parallel for schedule(static) if ((double)n > TCB_PAR_MIN)
    for (int64_t i = 0; i < n; i++) dx[i] = y[i] > 0.0f ? dy[i] : 0.0f;
}

void tcb_linear_init_uniform(const tcb_linear *l, tcb_rng *rng)
{
    double bound = 1.0 / sqrt((double)l->in);
    size_t nw = (size_t)l->in * (size_t)l->out;
    for (size_t i = 0; i < nw; i++) l->W[i] = (float)((2.0 * tcb_rng_uniform(rng) - 1.0) * bound);
    for (int i = 0; l->b && i < l->out; i++) l->b[i] = (float)((2.0 * tcb_rng_uniform(rng) - 1.0) * bound);
}

void tcb_leaky_relu_forward(float *y, const float *x, int64_t n, float slope)
{
#pragma omp parallel for schedule(static) if ((double)n > TCB_PAR_MIN)
    for (int64_t i = 0; i < n; i++) y[i] = x[i] > 0.0f ? x[i] : slope * x[i];
}

void tcb_leaky_relu_backward(float *dx, const float *dy, const float *y, int64_t n, float slope)
{
#pragma omp parallel for schedule(static) if ((double)n > TCB_PAR_MIN)
    for (int64_t i = 0; i < n; i++) dx[i] = y[i] > 0.0f ? dy[i] : slope * dy[i];
}

/* The elementwise loops run over CHUNK columns at a time so σ and σ′ of the
 * value rows can sit in small arrays while the tangent rows use them. */
void tcb_softplus_forward(float *y, const float *x, int n, int nt, int d)
{
    size_t blk = (size_t)n * d;
#pragma omp parallel for schedule(static) if ((double)n * d > TCB_PAR_MIN)
    for (int r = 0; r < n; r++) {
        for (int lo = 0; lo < d; lo += CHUNK) {
            size_t at = (size_t)r * d + lo;
            int w = imin(d - lo, CHUNK);
            float sig[CHUNK];
            const float *xs = x + at;
            float *ys = y + at;
#pragma omp simd
            for (int j = 0; j < w; j++) ys[j] = tcb_softplus(xs[j], &sig[j]);
            for (int t = 1; t <= nt; t++) {
                const float *xt = x + t * blk + at;
                float *yt = y + t * blk + at;
#pragma omp simd
                for (int j = 0; j < w; j++) yt[j] = sig[j] * xt[j];
            }
        }
    }
}

void tcb_softplus_backward(float *dx, const float *dy, const float *x, int n, int nt,
                                 int d)
{
    size_t blk = (size_t)n * d;
#pragma omp parallel for schedule(static) if ((double)n * d > TCB_PAR_MIN)
    for (int r = 0; r < n; r++) {
        for (int lo = 0; lo < d; lo += CHUNK) {
            size_t at = (size_t)r * d + lo;
            int w = imin(d - lo, CHUNK);
            float sig[CHUNK], curv[CHUNK], ds[CHUNK];
            const float *xs = x + at, *dys = dy + at;
#pragma omp simd
            for (int j = 0; j < w; j++) {
                sig[j] = tcb_sigmoid(xs[j], &curv[j]);
                ds[j] = sig[j] * dys[j];
            }
            for (int t = 1; t <= nt; t++) {
                const float *xt = x + t * blk + at, *dyt = dy + t * blk + at;
                float *dxt = dx + t * blk + at;
#pragma omp simd
                for (int j = 0; j < w; j++) {
                    float g = dyt[j];
                    ds[j] += curv[j] * xt[j] * g;
                    dxt[j] = sig[j] * g;
                }
            }
            memcpy(dx + at, ds, (size_t)w * sizeof(float));
        }
    }
}

void tcb_maxpool_forward(float *y, int32_t *arg, const float *x, int nb, int n, int d)
{
#pragma omp parallel for schedule(static) if ((double)nb * n * d > TCB_PAR_MIN)
    for (int b = 0; b < nb; b++) {
        const float *xb = x + (size_t)b * n * d;
        float *yb = y + (size_t)b * d;
        int32_t *ab = arg + (size_t)b * d;
        for (int j = 0; j < d; j++) yb[j] = xb[j], ab[j] = 0;
        for (int i = 1; i < n; i++) {
            const float *row = xb + (size_t)i * d;
            for (int j = 0; j < d; j++)
                if (row[j] > yb[j]) yb[j] = row[j], ab[j] = i;
        }
    }
}

void tcb_maxpool_linear_backward(float *dx, float *dW, float *db, const float *dy,
                                       const int32_t *arg, const float *x, const float *W,
                                       int nb, int n, int in, int out)
{
    tcb_colsum_acc(db, dy, nb, out);
    /* dW: each channel's row owned by one thread, the sets summed in order */
#pragma omp parallel for schedule(static) if ((double)nb * in * out > TCB_PAR_MIN)
    for (int o = 0; o < out; o++) {
        float *dw = dW + (size_t)o * in;
        for (int b = 0; b < nb; b++) {
            float g = dy[(size_t)b * out + o];
            const float *xr = x + ((size_t)b * n + arg[(size_t)b * out + o]) * in;
            for (int k = 0; k < in; k++) dw[k] += g * xr[k];
        }
    }
    /* dx: each set owned by one thread, the channels added in order */
    memset(dx, 0, (size_t)nb * n * in * sizeof(float));
#pragma omp parallel for schedule(static) if ((double)nb * in * out > TCB_PAR_MIN)
    for (int b = 0; b < nb; b++)
        for (int o = 0; o < out; o++) {
            float g = dy[(size_t)b * out + o];
            float *dxr = dx + ((size_t)b * n + arg[(size_t)b * out + o]) * in;
            const float *w = W + (size_t)o * in;
            for (int k = 0; k < in; k++) dxr[k] += g * w[k];
        }
}
