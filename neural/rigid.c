/* Quaternion-and-translation motion per row and its gradient (neural/rigid.h). */
#include "neural/rigid.h"

#include <math.h>

/* q̂ of one row's outputs and ‖q‖. */
static double unit_quaternion(const float *o, double qh[4], double q[4])
{
    q[0] = 1.0 + o[0], q[1] = o[1], q[2] = o[2], q[3] = o[3];
    double n = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    for (int k = 0; k < 4; k++) qh[k] = q[k] / (n + TCB_RIGID_EPS);
    return n;
}

/* R (row-major) of a quaternion (r, i, j, k), PyTorch3D's formula. */
static void rotation(const double q[4], double R[9])
{
    double r = q[0], i = q[1], j = q[2], k = q[3];
    double s = 2.0 / (r * r + i * i + j * j + k * k);
    R[0] = 1.0 - s * (j * j + k * k), R[1] = s * (i * j - k * r), R[2] = s * (i * k + j * r);
    R[3] = s * (i * j + k * r), R[4] = 1.0 - s * (i * i + k * k), R[5] = s * (j * k - i * r);
    R[6] = s * (i * k - j * r), R[7] = s * (j * k + i * r), R[8] = 1.0 - s * (i * i + j * j);
}

void tcb_rigid_forward(float *y, const float *o, const float *x, int64_t n, int nx)
{
#pragma omp parallel for schedule(static)
    for (int64_t p = 0; p < n; p++) {
        const float *op = o + p * TCB_RIGID_OUT, *xp = x + 3 * (p % nx);
        double q[4], qh[4], R[9];
        unit_quaternion(op, qh, q);
        rotation(qh, R);
        for (int a = 0; a < 3; a++)
            y[3 * p + a] = (float)(R[3 * a] * xp[0] + R[3 * a + 1] * xp[1] + R[3 * a + 2] * xp[2] +
                                   tanh(TCB_RIGID_TSCALE * op[4 + a]));
    }
}

/* ∂ℓ/∂q̂ from G = ∂ℓ/∂R: R = I + s·P(q̂) with s = 2/‖q̂‖², so
 * ∂ℓ/∂q̂ₘ = s·Σ G∘∂P/∂q̂ₘ − (4 q̂ₘ / ‖q̂‖⁴)·Σ G∘P. */
static void rotation_backward(const double q[4], const double G[9], double dq[4])
{
    double r = q[0], i = q[1], j = q[2], k = q[3];
    double nn = r * r + i * i + j * j + k * k, s = 2.0 / nn;
    /* P: the matrix R − I divided by s. */
    double P[9] = {-(j * j + k * k), i * j - k * r,    i * k + j * r,
                   i * j + k * r,    -(i * i + k * k), j * k - i * r,
                   i * k - j * r,    j * k + i * r,    -(i * i + j * j)};
    double gp = 0.0;
    for (int e = 0; e < 9; e++) gp += G[e] * P[e];
    /* Σ G∘∂P/∂q for each component (r, i, j, k). */
    double d_r = -G[1] * k + G[2] * j + G[3] * k - G[5] * i - G[6] * j + G[7] * i;
    double d_i = G[1] * j + G[2] * k + G[3] * j - 2.0 * G[4] * i - G[5] * r + G[6] * k + G[7] * r -
                 2.0 * G[8] * i;
    double d_j = -2.0 * G[0] * j + G[1] * i + G[2] * r + G[3] * i + G[5] * k - G[6] * r + G[7] * k -
                 2.0 * G[8] * j;
    double d_k = -2.0 * G[0] * k - G[1] * r + G[2] * i + G[3] * r - 2.0 * G[4] * k + G[5] * j +
                 G[6] * i + G[7] * j;
    const double d[4] = {d_r, d_i, d_j, d_k};
    for (int m = 0; m < 4; m++) dq[m] = s * d[m] - 4.0 * q[m] / (nn * nn) * gp;
}

void tcb_rigid_backward(float *do_, const float *dy, const float *o, const float *x, int64_t n,
                        int nx)
{
#pragma omp parallel for schedule(static)
    for (int64_t p = 0; p < n; p++) {
        const float *op = o + p * TCB_RIGID_OUT, *xp = x + 3 * (p % nx), *g = dy + 3 * p;
        float *d = do_ + p * TCB_RIGID_OUT;
        double q[4], qh[4], G[9], dqh[4];
        double norm = unit_quaternion(op, qh, q), den = norm + TCB_RIGID_EPS;
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++) G[3 * a + b] = (double)g[a] * xp[b];
        rotation_backward(qh, G, dqh);
        /* q̂ = q/(‖q‖ + ε): ∂q̂ₐ/∂q_b = δ_ab/den − q_a q_b/(‖q‖ den²). */
        double qd = 0.0;
        for (int m = 0; m < 4; m++) qd += q[m] * dqh[m];
        for (int m = 0; m < 4; m++)
            d[m] = (float)(dqh[m] / den - (norm > 0.0 ? q[m] * qd / (norm * den * den) : 0.0));
        for (int a = 0; a < 3; a++) {
            double t = tanh(TCB_RIGID_TSCALE * op[4 + a]);
            d[4 + a] = (float)(g[a] * TCB_RIGID_TSCALE * (1.0 - t * t));
        }
    }
}
