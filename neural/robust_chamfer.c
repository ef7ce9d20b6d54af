/* The robust Chamfer (neural/robust_chamfer.h). */
#include "neural/robust_chamfer.h"

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
                       : tcb_fail(err, TCB_ERR_NOMEM, "robust Chamfer: out of memory");
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

int tcb_robust_chamfer(const float *X, int nx, const float *P, int np, const tcb_nn *points_index,
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
