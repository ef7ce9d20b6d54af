/* The exponential of so(3) (neural/so3.h). */
#include "neural/so3.h"

#include <math.h>

typedef struct coeffs {
    double a, b, alpha, beta; /* a, b and a'(θ)/θ, b'(θ)/θ */
} coeffs;

static coeffs coeffs_of(double t2)
{
    double t = sqrt(t2);
    if (t < TCB_SO3_TAYLOR)
        return (coeffs){1 - t2 / 6 + t2 * t2 / 120, 0.5 - t2 / 24 + t2 * t2 / 720, -1.0 / 3 + t2 / 30,
                        -1.0 / 12 + t2 / 180};
    double s = sin(t), c = cos(t);
    return (coeffs){s / t, (1 - c) / t2, (t * c - s) / (t2 * t), (t * s - 2 * (1 - c)) / (t2 * t2)};
}

/* K = [r]× and K² as 3×3 row-major. */
static void skew(const double r[3], double K[9], double K2[9])
{
    K[0] = 0, K[1] = -r[2], K[2] = r[1];
    K[3] = r[2], K[4] = 0, K[5] = -r[0];
    K[6] = -r[1], K[7] = r[0], K[8] = 0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            double s = 0;
            for (int k = 0; k < 3; k++) s += K[3 * i + k] * K[3 * k + j];
            K2[3 * i + j] = s;
        }
}

void tcb_so3_exp_forward(float *R, const float *r, int64_t n)
{
    for (int64_t p = 0; p < n; p++) {
        double v[3] = {r[3 * p], r[3 * p + 1], r[3 * p + 2]}, K[9], K2[9];
        skew(v, K, K2);
        coeffs c = coeffs_of(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        for (int e = 0; e < 9; e++) R[9 * p + e] = (float)((e % 4 == 0) + c.a * K[e] + c.b * K2[e]);
    }
}

void tcb_so3_exp_backward(float *dr, const float *dR, const float *r, int64_t n)
{
    /* E_i: the generators ∂K/∂r_i. */
    static const double E[3][9] = {{0, 0, 0, 0, 0, -1, 0, 1, 0}, {0, 0, 1, 0, 0, 0, -1, 0, 0},
                                   {0, -1, 0, 1, 0, 0, 0, 0, 0}};
    for (int64_t p = 0; p < n; p++) {
        double v[3] = {r[3 * p], r[3 * p + 1], r[3 * p + 2]}, K[9], K2[9], G[9];
        for (int e = 0; e < 9; e++) G[e] = dR[9 * p + e];
        skew(v, K, K2);
        coeffs c = coeffs_of(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        double gk = 0, gk2 = 0;
        for (int e = 0; e < 9; e++) gk += G[e] * K[e], gk2 += G[e] * K2[e];
        for (int i = 0; i < 3; i++) {
            double ge = 0, gsym = 0;
            for (int a = 0; a < 3; a++)
                for (int b = 0; b < 3; b++) {
                    double s = 0; /* (E_i K + K E_i)[a][b] */
                    for (int k = 0; k < 3; k++) s += E[i][3 * a + k] * K[3 * k + b] + K[3 * a + k] * E[i][3 * k + b];
                    gsym += G[3 * a + b] * s;
                    ge += G[3 * a + b] * E[i][3 * a + b];
                }
            dr[3 * p + i] = (float)(c.a * ge + c.b * gsym + v[i] * (c.alpha * gk + c.beta * gk2));
        }
    }
}
