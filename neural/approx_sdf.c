/* DynoSurf's approximate signed distance (neural/approx_sdf.h). */
#include "neural/approx_sdf.h"

#include <math.h>
#include <stdlib.h>

/* One query's weights w [k], Gaussians g [k], plane distances l [k] and
 * value s, in double. */
static double query(const float *y, const int32_t *nb, const float *p, const float *normals, int k, double r,
                    double *w, double *g, double *l)
{
    double top = -INFINITY, sum = 0, s = 0;
    for (int j = 0; j < k; j++) {
        const float *pj = p + 3 * (size_t)nb[j], *nj = normals + 3 * (size_t)nb[j];
        double d2 = 0, dot = 0;
        for (int c = 0; c < 3; c++) {
            double d = (double)y[c] - pj[c];
            d2 += d * d;
            dot += nj[c] * d;
        }
        g[j] = exp(-d2 / (r * r));
        l[j] = dot;
        top = g[j] > top ? g[j] : top;
    }
    for (int j = 0; j < k; j++) sum += w[j] = exp(g[j] - top);
    for (int j = 0; j < k; j++) s += (w[j] /= sum) * l[j];
    return s;
}

int tcb_approx_sdf_forward(float *s, int32_t *nbr, const float *y, int m, const tcb_nn *index, const float *p,
                           const float *normals, int k, double r, tcb_error *err)
{
    if (k < 1 || k > TCB_APPROX_SDF_K_MAX || k > tcb_nn_size(index))
        return tcb_fail(err, TCB_ERR_INPUT, "approximate SDF: %d neighbours of %d points (at most %d)", k,
                        tcb_nn_size(index), TCB_APPROX_SDF_K_MAX);
    float *d2 = malloc((size_t)m * k * sizeof *d2);
    if (!d2) return tcb_fail(err, TCB_ERR_NOMEM, "approximate SDF: out of memory for %d queries", m);
    int rc = tcb_nn_queryk(index, y, m, k, nbr, d2, err);
    free(d2);
    if (rc) return rc;
    double w[TCB_APPROX_SDF_K_MAX], g[TCB_APPROX_SDF_K_MAX], l[TCB_APPROX_SDF_K_MAX];
    for (int q = 0; q < m; q++) s[q] = (float)query(y + 3 * (size_t)q, nbr + (size_t)q * k, p, normals, k, r, w, g, l);
    return TCB_OK;
}

void tcb_approx_sdf_backward(float *dy, const float *ds, const float *y, int m, const int32_t *nbr, const float *p,
                             const float *normals, int k, double r)
{
    double w[TCB_APPROX_SDF_K_MAX], g[TCB_APPROX_SDF_K_MAX], l[TCB_APPROX_SDF_K_MAX];
    for (int q = 0; q < m; q++) {
        const float *yq = y + 3 * (size_t)q;
        const int32_t *nb = nbr + (size_t)q * k;
        double s = query(yq, nb, p, normals, k, r, w, g, l), grad[3] = {0, 0, 0};
        for (int j = 0; j < k; j++) {
            const float *pj = p + 3 * (size_t)nb[j], *nj = normals + 3 * (size_t)nb[j];
            double pull = -2.0 / (r * r) * w[j] * g[j] * (l[j] - s);
            for (int c = 0; c < 3; c++) grad[c] += w[j] * nj[c] + pull * ((double)yq[c] - pj[c]);
        }
        for (int c = 0; c < 3; c++) dy[3 * (size_t)q + c] = (float)(ds[q] * grad[c]);
    }
}
