/* The robust Chamfer (neural/robust_chamfer.h). */
#include "neural/robust_chamfer.h"

#include <math.h>
#include <stdlib.h>

#include "neural/abs_cos.h"

static double welsch(double s, double alpha) { return exp(-s * s / (2.0 * alpha * alpha)); }

/* One direction, queries → `to`: Σ w(s) s with s the squared distance to
 * the nearest of `to`; the gradient w·2(q − nearest) goes to the query
 * (dq, may be NULL) and its negative to the nearest point (dto, may be
 * NULL). With normals (qn, ton), *normal = the mean of 1 − |cos| between
 * each query's normal and its nearest's, its gradient to the moved side's
 * normals (dqn for the queries' or dton for `to`'s, either may be NULL). */
typedef struct side {
    const float *pts, *normals;
    float *dpts, *dnormals;
} side;

static int one_way(side q, int nq, side to, const tcb_nn *to_index, double alpha, double *sum, double *normal,
                   tcb_error *err)
{
    int32_t *idx = malloc((size_t)nq * sizeof *idx);
    int rc = idx ? tcb_nn_query1(to_index, q.pts, nq, idx, NULL, err)
                 : tcb_fail(err, TCB_ERR_NOMEM, "robust Chamfer: out of memory");
    *sum = *normal = 0.0;
    int with_normals = q.normals && to.normals;
    for (int i = 0; !rc && i < nq; i++) {
        size_t j = (size_t)idx[i];
        const float *a = q.pts + 3 * (size_t)i, *b = to.pts + 3 * j;
        double s = 0.0, d[3];
        for (int k = 0; k < 3; k++) d[k] = (double)a[k] - b[k], s += d[k] * d[k];
        double w = welsch(s, alpha);
        *sum += w * s;
        for (int k = 0; k < 3; k++) {
            if (q.dpts) q.dpts[3 * (size_t)i + k] += (float)(2.0 * w * d[k]);
            if (to.dpts) to.dpts[3 * j + k] -= (float)(2.0 * w * d[k]);
        }
        if (!with_normals) continue;
        const float *na = q.normals + 3 * (size_t)i, *nb = to.normals + 3 * j;
        if (q.dnormals) *normal += tcb_abs_cos_term(na, nb, 1.0 / nq, q.dnormals + 3 * (size_t)i) / nq;
        else *normal += tcb_abs_cos_term(nb, na, 1.0 / nq, to.dnormals ? to.dnormals + 3 * j : NULL) / nq;
    }
    free(idx);
    return rc;
}

int tcb_robust_chamfer_normals(const float *X, const float *NX, int nx, const float *P, const float *NP, int np,
                               const tcb_nn *points_index, double alpha, double *cd, double *normal, float *dX,
                               float *dNX, tcb_error *err)
{
    for (size_t i = 0; i < 3 * (size_t)nx; i++) dX[i] = 0.0f;
    if (dNX)
        for (size_t i = 0; i < 3 * (size_t)nx; i++) dNX[i] = 0.0f;
    tcb_nn *template_index = NULL;
    double to_points = 0.0, to_template = 0.0, n1 = 0.0, n2 = 0.0;
    side moved = {X, NX, dX, dNX}, data = {P, NP, NULL, NULL};
    int rc = one_way(moved, nx, data, points_index, alpha, &to_points, &n1, err);
    if (!rc) rc = tcb_nn_build(X, nx, &template_index, err);
    if (!rc) rc = one_way(data, np, moved, template_index, alpha, &to_template, &n2, err);
    tcb_nn_free(template_index);
    *cd = to_points + to_template;
    if (normal) *normal = n1 + n2;
    return rc;
}

int tcb_robust_chamfer(const float *X, int nx, const float *P, int np, const tcb_nn *points_index,
                       double alpha, double *cd, float *dX, tcb_error *err)
{
    return tcb_robust_chamfer_normals(X, NULL, nx, P, NULL, np, points_index, alpha, cd, NULL, dX, NULL, err);
}
