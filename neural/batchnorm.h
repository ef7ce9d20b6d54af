/* Batch normalization over rows (PyTorch's BatchNorm1d on [rows][C], where
 * rows are the points of a whole batch or the shapes of a batch), in the two
 * modes of PyTorch's train() and eval():
 *
 *   training   μ, σ² = mean and biased variance of each channel over the n
 *              rows; y = γ·(x − μ)/√(σ² + eps) + β; the running statistics
 *              move towards the batch's: r_μ ← (1−m)·r_μ + m·μ,
 *              r_σ² ← (1−m)·r_σ² + m·σ²·n/(n−1) (unbiased), m = 0.1.
 *   evaluation y = γ·(x − r_μ)/√(r_σ² + eps) + β: per row, so any number of
 *              rows (a whole mesh) can go through.
 *
 * Backward is the exact gradient of the training mode (the batch statistics
 * depend on every row), with x̂ = (x − μ)/σ and the column sums of dy and
 * dy·x̂:  dx = γ/σ · (dy − Σdy/n − x̂·Σ(dy·x̂)/n),  dβ += Σdy,  dγ += Σ dy·x̂.
 *
 * Reductions over rows run over a fixed partition of the rows and are
 * summed in double, so results do not depend on the thread count. The
 * per-channel scratch lives on the stack (≈ 0.4 MiB at TCB_BN_MAX_C). */
#ifndef TCB_NEURAL_BATCHNORM_H
#define TCB_NEURAL_BATCHNORM_H

#include <stddef.h>
#include <stdint.h>

#define TCB_BN_EPS 1e-5
#define TCB_BN_MAX_C 4096 /* channels of one layer */
#define TCB_BN_MOMENTUM 0.1

/* A layer's tensors: γ and β are trained parameters (PyTorch's weight and
 * bias), the running mean and variance are buffers (trained by no
 * gradient, kept in checkpoints). In a gradient view mean and var are NULL. */
typedef struct tcb_batchnorm {
    float *gamma, *beta; /* [C] */
    float *mean, *var;   /* [C] running statistics */
    int C;
} tcb_batchnorm;

/* Views the layer at params + *poff (γ, β: 2C floats) and, when buffers is
 * not NULL, buffers + *boff (running mean, var: 2C floats), advancing the
 * offsets. 1 ≤ C ≤ TCB_BN_MAX_C. */
void tcb_batchnorm_bind(tcb_batchnorm *bn, float *params, size_t *poff, float *buffers, size_t *boff, int C);

/* PyTorch's initial running statistics: mean 0, variance 1. */
void tcb_batchnorm_reset_running(const tcb_batchnorm *bn);

/* Training mode, x [n][C] → y [n][C] (y may alias x), n ≥ 2, with the
 * ReLU that follows it fused in when relu (y = max(0, BN(x))): one pass
 * over the data instead of two. Keeps what backward needs: xhat [n][C] (x̂)
 * and rstd [C] (1/√(σ² + eps)); the batch mean and biased variance go to
 * mu, var2 [C] (for update_running). */
void tcb_batchnorm_forward_train(const tcb_batchnorm *bn, float *y, float *xhat, float *rstd, float *mu,
                                 float *var2, const float *x, int n, int relu);

/* Training-mode batch norm without ReLU followed by the max over each of
 * nb sets of n rows (PointNet's last layer and its global pool), without
 * writing BN(x) or x̂: x [nb·n][C] → g [nb][C], arg [nb][C] (the row
 * within its set), bit for bit what forward_train and tcb_maxpool_forward
 * give. Keeps rstd, mu, var2 [C] as forward_train and mlo [C], the mean's
 * low float part; the backward recomputes x̂ from x, which the caller
 * keeps. Two passes over x instead of forward_train's and the pool's four
 * (and the backward two instead of six): at PointNet's 1024 channels
 * these passes are the encoder's memory traffic. */
void tcb_batchnorm_maxpool_forward_train(const tcb_batchnorm *bn, float *g, int32_t *arg, float *rstd, float *mu,
                                         float *mlo, float *var2, const float *x, int nb, int n);

/* Its backward: dx [nb·n][C] from dg [nb][C] = ∂L/∂g, grad->gamma and
 * grad->beta [C] accumulated; equal bit for bit to scattering dg to the
 * max rows and tcb_batchnorm_backward with the stored x̂. */
void tcb_batchnorm_maxpool_backward(const tcb_batchnorm *bn, const tcb_batchnorm *grad, float *dx, const float *dg,
                                    const int32_t *arg, const float *x, const float *rstd, const float *mu,
                                    const float *mlo, int nb, int n);

/* Moves bn's running statistics towards batch statistics (mu, var2 from a
 * training forward over n rows). Separate from the forward so a batch whose
 * forward is reused (the same input twice) can count twice, as PyTorch does
 * when a module is called twice. */
void tcb_batchnorm_update_running(const tcb_batchnorm *bn, const float *mu, const float *var2, int n);

/* Evaluation mode with the running statistics, x [n][C] → y [n][C], the
 * ReLU fused in when relu. */
void tcb_batchnorm_forward_eval(const tcb_batchnorm *bn, float *y, const float *x, int n, int relu);

/* Training-mode backward: dx [n][C] (may alias dy), grad->gamma and
 * grad->beta [C] accumulated, from dy [n][C] and the forward's xhat, rstd.
 * y: the forward's output when its ReLU was fused in (dy is masked by
 * y > 0 first), else NULL. */
void tcb_batchnorm_backward(const tcb_batchnorm *bn, const tcb_batchnorm *grad, float *dx, const float *dy,
                            const float *y, const float *xhat, const float *rstd, int n);

#endif
