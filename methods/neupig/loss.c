/* Neu-PiG's frame confidence and isometry term (methods/neupig/loss.h). */
#include "methods/neupig/loss.h"

#include <math.h>
#include <stdlib.h>

void tcb_neupig_confidence(const double *cd, int T, int key, long long epoch, long long epochs,
                           double *c)
{
    double power = 1.0 - sqrt((double)epoch / (double)epochs);
    c[key] = 1.0;
    for (int dir = -1; dir <= 1; dir += 2) {
        double acc = 1.0;
        for (int t = key + dir; t >= 0 && t < T; t += dir) {
            acc *= pow(1.0 / (1.0 + fmax(0.0, cd[t] - cd[key])), power);
            c[t] = acc;
        }
    }
}

double tcb_neupig_edge_l1(const float *X, int T, int nv, const int32_t *edges, int ne,
                          const float *base, double weight, float *dX)
{
    double sum = 0.0, g = weight / ((double)T * ne);
    for (int t = 0; t < T; t++) {
        const float *x = X + (size_t)t * nv * 3;
        float *dx = dX + (size_t)t * nv * 3;
        for (int e = 0; e < ne; e++) {
            const float *a = x + 3 * (size_t)edges[2 * e], *b = x + 3 * (size_t)edges[2 * e + 1];
            double d[3], len = 0.0;
            for (int k = 0; k < 3; k++) d[k] = (double)a[k] - b[k], len += d[k] * d[k];
            len = sqrt(len);
            double diff = len - base[e];
            sum += fabs(diff);
            if (diff == 0.0 || len == 0.0) continue;
            double s = g * (diff > 0.0 ? 1.0 : -1.0) / len;
            for (int k = 0; k < 3; k++) {
                dx[3 * (size_t)edges[2 * e] + k] += (float)(s * d[k]);
                dx[3 * (size_t)edges[2 * e + 1] + k] -= (float)(s * d[k]);
            }
        }
    }
    return weight * sum / ((double)T * ne);
}
