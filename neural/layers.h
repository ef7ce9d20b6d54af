/* Neural-network layers shared by the trained methods (the atlas family,
 * cc): each a forward/backward pair over caller-owned float32 buffers
 * (llm.c style), row-major, one row per point or sample.
 *
 * Forward-mode tangents ride along as extra rows. A "stacked" buffer of n
 * value rows with nt tangent blocks is [(1 + nt)·n][d]: rows [0, n) hold the
 * values, rows [(1 + j)·n, (2 + j)·n) the derivative of those values along
 * tangent direction j (the patch decoder uses nt = 2: ∂/∂u and ∂/∂v). A
 * linear layer maps values and tangents with the same W, so a whole stack is
 * ONE GEMM; only the value rows get the bias (the derivative of a constant is
 * zero). Backward functions ACCUMULATE into parameter gradients (the caller
 * zeroes them once per step) and OVERWRITE input gradients.
 *
 * Threading: GEMMs go to OpenBLAS (its OpenMP pool); the fused loops are
 * OpenMP over rows, and every reduction over rows is split by columns with a
 * fixed summation order, so results do not depend on the thread count except
 * through OpenBLAS's own blocking. */
#ifndef TCB_NEURAL_LAYERS_H
#define TCB_NEURAL_LAYERS_H

#include <stddef.h>
#include <stdint.h>

#include "neural/softplus.h"

/* A linear layer's tensors, viewed inside a flat buffer (parameters or their
 * gradients): W [out][in] then b [out], PyTorch's layout. */
typedef struct tcb_linear {
    float *W, *b;
    int in, out;
} tcb_linear;

/* Views l at base + *offset and advances *offset by its in·out + out floats. */
void tcb_linear_bind(tcb_linear *l, float *base, size_t *offset, int in, int out);

/* The same without a bias (Linear(..., bias=False)): b = NULL, in·out floats. */
void tcb_linear_bind_nobias(tcb_linear *l, float *base, size_t *offset, int in, int out);

/* PyTorch's default initialisation of a Linear layer: W then b (when it
 * has one), each entry U(−1/√in, 1/√in), drawn in that order from rng. */
struct tcb_rng;
void tcb_linear_init_uniform(const tcb_linear *l, struct tcb_rng *rng);

/* y[(1+nt)·n][out] = x[(1+nt)·n][in] · W[out][in]ᵀ, plus b[out] on the n value
 * rows (PyTorch's Linear layout; b may be NULL). Tiny dimensions (in or out
 * ≤ 3: the xyz input, the xyz output) use fused loops, the rest cblas_sgemm. */
void tcb_linear_forward(float *y, const float *x, const float *W, const float *b, int n,
                              int nt, int in, int out);

/* dW[out][in] += dyᵀ·x over all (1+nt)·n rows; db[out] += Σ dy over the n value
 * rows (db may be NULL iff b was); dx[(1+nt)·n][in] = dy·W (dx may be NULL). */
void tcb_linear_backward(float *dx, float *dW, float *db, const float *dy, const float *x,
                               const float *W, int n, int nt, int in, int out);

/* y[n] = max(x, 0); y may alias x. */
void tcb_relu_forward(float *y, const float *x, int64_t n);

/* dx[n] = dy · [y > 0] from the forward output y; dx may alias dy. */
void tcb_relu_backward(float *dx, const float *dy, const float *y, int64_t n);

/* y[n] = x > 0 ? x : slope·x (PyTorch's LeakyReLU, slope 0.01 by default);
 * y may alias x. */
void tcb_leaky_relu_forward(float *y, const float *x, int64_t n, float slope);

/* dx[n] = dy · (y > 0 ? 1 : slope) from the forward output y (slope > 0:
 * y > 0 exactly where x > 0); dx may alias dy. */
void tcb_leaky_relu_backward(float *dx, const float *dy, const float *y, int64_t n, float slope);

/* Stacked softplus: x = [s; t_1..t_nt] (pre-activations and their tangents,
 * [(1+nt)·n][d]) → y = [softplus(s); σ(s)⊙t_1; …; σ(s)⊙t_nt]. */
void tcb_softplus_forward(float *y, const float *x, int n, int nt, int d);

/* Exact reverse mode through values and tangents, the product rule on
 * t_a = σ(s)·t_s:
 *     ds   = σ·da + σ(1−σ)·Σ_j t_j·dt_aj,      dt_sj = σ·dt_aj.
 * dx, dy, x: [(1+nt)·n][d]; dx may alias dy. */
void tcb_softplus_backward(float *dx, const float *dy, const float *x, int n, int nt,
                                 int d);

/* Max over the n points of each of nb sets: x [nb][n][d] → y [nb][d], with
 * arg [nb][d] the winning point (the first one on ties, as torch.max). */
void tcb_maxpool_forward(float *y, int32_t *arg, const float *x, int nb, int n, int d);

/* Backward of y = maxpool(x·Wᵀ + b) over the n points of each of nb sets
 * (x [nb][n][in], W [out][in], y [nb][out]), given dy and the forward's arg.
 * The pool routes each (set, channel) gradient to ONE point, so rather than
 * the dense [nb·n][out] gradient and two GEMMs over it, only those rows are
 * touched: dW[o] += Σ_b dy[b][o]·x[b][arg[b][o]], db += Σ_b dy[b], and
 * dx [nb][n][in] = dy routed through W (zero at points that won nothing). */
void tcb_maxpool_linear_backward(float *dx, float *dW, float *db, const float *dy,
                                       const int32_t *arg, const float *x, const float *W,
                                       int nb, int n, int in, int out);

/* db[d] += Σ_{r<n} dy[r][d], summed in double per column. */
void tcb_colsum_acc(float *db, const float *dy, int n, int d);

#endif
