#include "neural/chamfer_l1.h"

#include "neural/abs_cos.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static double l1(const float *a, const float *b)
{
    return fabs((double)a[0] - b[0]) + fabs((double)a[1] - b[1]) + fabs((double)a[2] - b[2]);
}

/* The L1-nearest of all n points: the fallback when the candidates cannot
 * certify their best. */
static int32_t brute_l1(const float *pts, int n, const float *q, double *best)
{
    int32_t arg = 0;
    *best = INFINITY;
    for (int i = 0; i < n; i++) {
        double d = l1(pts + 3 * i, q);
        if (d < *best) *best = d, arg = i;
    }
    return arg;
}

int tcb_nearest_l1(const tcb_nn *index, const float *pts, int n, const float *queries, int nq, int32_t *idx,
                   float *d1, tcb_error *err)
{
    int k = n < TCB_CHAMFER_L1_CANDIDATES ? n : TCB_CHAMFER_L1_CANDIDATES;
    int32_t *cand = malloc((size_t)nq * k * sizeof *cand);
    float *d2 = malloc((size_t)nq * k * sizeof *d2);
    int rc = cand && d2 ? tcb_nn_queryk(index, queries, nq, k, cand, d2, err)
                        : tcb_fail(err, TCB_ERR_NOMEM, "L1 nearest: out of memory for %d queries", nq);
    for (int q = 0; !rc && q < nq; q++) {
        const float *x = queries + 3 * (size_t)q;
        const int32_t *c = cand + (size_t)q * k;
        int32_t arg = c[0];
        double best = l1(pts + 3 * c[0], x);
        for (int j = 1; j < k; j++) {
            double d = l1(pts + 3 * c[j], x);
            if (d < best || (d == best && c[j] < arg)) best = d, arg = c[j];
        }
        /* Any point closer in L1 is closer than `best` in L2 too: beyond
         * the k-th L2 neighbour only when that one lies farther than best
         * (with a margin for the float distances). */
        if (k < n && sqrt((double)d2[(size_t)q * k + k - 1]) <= best * (1 + 1e-5) + 1e-12)
            arg = brute_l1(pts, n, x, &best);
        idx[q] = arg;
        if (d1) d1[q] = (float)best;
    }
    free(cand), free(d2);
    return rc;
}

static double sgn(double v) { return (v > 0) - (v < 0); }

int tcb_chamfer_l1(const float *X, const float *NX, int nx, const float *Y, const float *NY, int ny,
                   const tcb_nn *y_index, double *cham, double *normal, float *dX, float *dNX, tcb_error *err)
{
    memset(dX, 0, (size_t)nx * 3 * sizeof *dX);
    if (dNX) memset(dNX, 0, (size_t)nx * 3 * sizeof *dNX);
    *cham = *normal = 0;
    int with_normals = NX && NY;
    tcb_nn *x_index = NULL;
    int32_t *to_y = malloc((size_t)nx * sizeof *to_y), *to_x = malloc((size_t)ny * sizeof *to_x);
    int rc = to_y && to_x ? tcb_nn_build(X, nx, &x_index, err)
                          : tcb_fail(err, TCB_ERR_NOMEM, "L1 Chamfer: out of memory for %d + %d points", nx, ny);
    if (!rc) rc = tcb_nearest_l1(y_index, Y, ny, X, nx, to_y, NULL, err);
    if (!rc) rc = tcb_nearest_l1(x_index, X, nx, Y, ny, to_x, NULL, err);
    if (!rc) {
        double sx = 1.0 / nx, sy = 1.0 / ny;
        for (int i = 0; i < nx; i++) {
            const float *x = X + 3 * i, *y = Y + 3 * to_y[i];
            *cham += sx * l1(x, y);
            for (int d = 0; d < 3; d++) dX[3 * i + d] += (float)(sx * sgn((double)x[d] - y[d]));
            if (with_normals) *normal += sx * tcb_abs_cos_term(NX + 3 * i, NY + 3 * to_y[i], sx, dNX ? dNX + 3 * i : NULL);
        }
        for (int j = 0; j < ny; j++) {
            int i = to_x[j];
            const float *x = X + 3 * i, *y = Y + 3 * j;
            *cham += sy * l1(x, y);
            for (int d = 0; d < 3; d++) dX[3 * i + d] += (float)(sy * sgn((double)x[d] - y[d]));
            if (with_normals) *normal += sy * tcb_abs_cos_term(NX + 3 * i, NY + 3 * j, sy, dNX ? dNX + 3 * i : NULL);
        }
    }
    tcb_nn_free(x_index);
    free(to_y), free(to_x);
    return rc;
}
