/* Training Chamfer loss with its gradient. Both directions use the exact
 * k-NN index (brute force at the training sizes, M = N = 2500); distances
 * and gradients are re-evaluated in double from the float points. */
#include "methods/atlas/loss_chamfer.h"

#include <stdint.h>
#include <stdlib.h>

#include "tcb/nn.h"

/* |p − q|², and dp += g · ∂|p − q|²/∂p = 2g (p − q) when dp is not NULL. */
static double pull(const float *p, const float *q, double g, float *dp)
{
    double d2 = 0.0;
    for (int c = 0; c < 3; c++) {
        double diff = (double)p[c] - q[c];
        d2 += diff * diff;
        if (dp) dp[c] += (float)(2.0 * g * diff);
    }
    return d2;
}

/* One shape: returns the two sums of squared NN distances in s[0] (pred →
 * target) and s[1] (target → pred); gm and gn are the gradient scales of
 * one term of each sum. idx has room for max(M, N) entries. */
static int shape_chamfer(const float *pred, const float *target, int M, int N, double gm,
                         double gn, int32_t *idx, double s[2], float *dpred, tcb_error *err)
{
    s[0] = s[1] = 0.0;
    int rc = tcb_nn_nearest(target, N, pred, M, idx, NULL, err);
    for (int m = 0; rc == TCB_OK && m < M; m++)
        s[0] += pull(pred + 3 * (size_t)m, target + 3 * (size_t)idx[m], gm,
                     dpred ? dpred + 3 * (size_t)m : NULL);
    if (rc == TCB_OK) rc = tcb_nn_nearest(pred, M, target, N, idx, NULL, err);
    /* Scatter: a predicted point nearest to several inputs collects them all. */
    for (int n = 0; rc == TCB_OK && n < N; n++)
        s[1] += pull(pred + 3 * (size_t)idx[n], target + 3 * (size_t)n, gn,
                     dpred ? dpred + 3 * (size_t)idx[n] : NULL);
    return rc;
}

int tcb_atlas_chamfer_loss(const float *pred, const float *target, int B, int M, int N,
                           float weight, double *loss, float *dpred, tcb_error *err)
{
    if (B < 1 || M < 1 || N < 1)
        return tcb_fail(err, TCB_ERR_INPUT, "atlas chamfer: empty batch (B=%d M=%d N=%d)", B, M,
                        N);
    int32_t *idx = malloc((size_t)(M > N ? M : N) * sizeof *idx);
    if (!idx) return tcb_fail(err, TCB_ERR_NOMEM, "atlas chamfer: out of memory");
    double gm = (double)weight / ((double)B * M), gn = (double)weight / ((double)B * N);
    double sum_m = 0.0, sum_n = 0.0;
    int rc = TCB_OK;
    for (int b = 0; rc == TCB_OK && b < B; b++) {
        double s[2];
        rc = shape_chamfer(pred + (size_t)b * M * 3, target + (size_t)b * N * 3, M, N, gm, gn,
                           idx, s, dpred ? dpred + (size_t)b * M * 3 : NULL, err);
        sum_m += s[0], sum_n += s[1];
    }
    free(idx);
    if (rc == TCB_OK) *loss = sum_m / ((double)B * M) + sum_n / ((double)B * N);
    return rc;
}
