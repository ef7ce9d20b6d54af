/* Neu-PiG's robust Chamfer, frame confidence and isometry term
 * (methods/neupig/loss.h). */
#include "methods/neupig/loss.h"

#include <math.h>
#include <stdlib.h>

static double welsch(double s, double alpha) { return exp(-s * s / (2.0 * alpha * alpha)); }

/* Σ over queries of w(s) s with s the squared distance to the nearest of
 * `to`; the gradient w·2(q − nearest) goes to the query (dq, may be NULL)
 * and its negative to the nearest point (dto, may be NULL). */
static int one_way(const float *q, int nq, const float *to, const tcb_nn *to_index, double alpha,
                   double *sum, float *dq, float *dto, tcb_error *err)
{
    int32_t *idx = malloc((size_t)nq * sizeof *idx);
    float *d2 = malloc((size_t)nq * sizeof *d2);
    int rc = idx && d2 ? tcb_nn_query1(to_index, q, nq, idx, d2, err)
                       : tcb_fail(err, TCB_ERR_NOMEM, "Neu-PiG Chamfer: out of memory");
    *sum = 0.0;
    for (int i = 0; !rc && i < nq; i++) {
        const float *a = q + 3 * (size_t)i, *b = to + 3 * (size_t)idx[i];
        double s = 0.0, d[3];
        for (int k = 0; k < 3; k++) d[k] = (double)a[k] - b[k], s += d[k] * d[k];
        double w = welsch(s, alpha);
        *sum += w * s;
        for (int k = 0; k < 3; k++) {
            if (dq) dq[3 * (size_t)i + k] += (float)(2.0 * w * d[k]);
            if (dto) dto[3 * (size_t)idx[i] + k] -= (float)(2.0 * w * d[k]);
        }
    }
    free(idx);
    free(d2);
    return rc;
}

int tcb_neupig_chamfer(const float *X, int nx, const float *P, int np, const tcb_nn *points_index,
                       double alpha, double *cd, float *dX, tcb_error *err)
{
    for (size_t i = 0; i < 3 * (size_t)nx; i++) dX[i] = 0.0f;
    tcb_nn *template_index = NULL;
    double to_points = 0.0, to_template = 0.0;
    int rc = one_way(X, nx, P, points_index, alpha, &to_points, dX, NULL, err);
    if (!rc) rc = tcb_nn_build(X, nx, &template_index, err);
    if (!rc) rc = one_way(P, np, X, template_index, alpha, &to_template, NULL, dX, err);
    tcb_nn_free(template_index);
    *cd = to_points + to_template;
    return rc;
}

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
