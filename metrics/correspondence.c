/* Correspondence metrics of one pair i → j (reference-protocol §5.5), from the
 * predicted GT-vertex id of every vertex.
 *
 * Squared distances are computed in double from the float vertices as
 * (dx² + dy²) + dz² with d = (double)a − (double)b; the rank compares values of
 * that one expression on both sides of its strict <, so the predicted vertex
 * itself is never counted as closer than itself. */
#include "tcb/metrics.h"

#include <math.h>
#include <stdlib.h>

#include "tcb/nn.h"

/* Below this many vertices the rank loop stays single-threaded. */
#define PAR_MIN_VERTS 256

/* numpy.linspace(0, max, steps)[s]: s·step, the last value max exactly. */
static double linspace(double max, int steps, int s)
{
    if (s >= steps - 1) return max;
    return (double)s * (max / (steps - 1));
}

double tcb_pck_threshold(int s) { return linspace(TCB_PCK_MAX, TCB_PCK_STEPS, s); }

double tcb_geo_pck_threshold(int s) { return linspace(TCB_GEO_PCK_MAX, TCB_GEO_PCK_STEPS, s); }

int tcb_project_to_vertices(const float *verts_j, int nv, const float *pts, int n,
                            int32_t *idx, tcb_error *err)
{
    return tcb_nn_nearest(verts_j, nv, pts, n, idx, NULL, err);
}

/* #{l : |v_l − q|² < dk} over SoA coordinates x, y, z [n]. */
static long long count_closer(const double *restrict x, const double *restrict y,
                              const double *restrict z, int n, double qx, double qy,
                              double qz, double dk)
{
    long long c = 0;
#pragma omp simd reduction(+ : c)
    for (int l = 0; l < n; l++) {
        double dx = x[l] - qx, dy = y[l] - qy, dz = z[l] - qz;
        c += dx * dx + dy * dy + dz * dz < dk;
    }
    return c;
}

/* First index of the ascending xs[0..n) with xs[i] >= v, or with xs[i] > v
 * when `past_equal`. */
static int search(const double *xs, int n, double v, int past_equal)
{
    int lo = 0, hi = n;
    while (lo < hi) {
        int mid = lo + (hi - lo) / 2;
        if (xs[mid] < v || (past_equal && xs[mid] == v)) lo = mid + 1;
        else hi = mid;
    }
    return lo;
}

typedef struct x_key { double x; int id; } x_key;

static int by_x(const void *a, const void *b)
{
    const x_key *p = a, *q = b;
    if (p->x != q->x) return p->x < q->x ? -1 : 1;
    return (p->id > q->id) - (p->id < q->id);
}

/* rank[k] = #{l : |v_l − v_k|² < d[k]} / nv.
 *
 * Only vertices with |x_l − x_k| < sqrt(d[k]) can be closer, so the vertices
 * are sorted by x once and each k scans just that slab; the count inside is
 * the same exact comparison as a full scan. The slab is widened by 1e-12
 * relative so rounding of sqrt can never exclude a vertex that counts (the
 * double differences of float coordinates are monotone in x_l). Worst case
 * (huge errors) stays O(nv²); typical methods cost O(nv log nv + nv·slab). */
static int ranks(const double *x, const double *y, const double *z, int nv, const double *d,
                 double *rank)
{
    x_key *keys = malloc((size_t)nv * sizeof *keys);
    double *sorted = malloc((size_t)nv * 3 * sizeof *sorted);
    if (!keys || !sorted) {
        free(keys), free(sorted);
        return -1;
    }
    for (int k = 0; k < nv; k++) keys[k] = (x_key){x[k], k};
    qsort(keys, (size_t)nv, sizeof *keys, by_x);
    double *xs = sorted, *ys = xs + nv, *zs = ys + nv;
    for (int r = 0; r < nv; r++) xs[r] = x[keys[r].id], ys[r] = y[keys[r].id], zs[r] = z[keys[r].id];
#pragma omp parallel for schedule(dynamic, 64) if (nv > PAR_MIN_VERTS)
    for (int k = 0; k < nv; k++) {
        /* An exact match has rank 0: nothing is closer than distance 0. */
        long long c = 0;
        if (d[k] > 0.0) {
            double half = sqrt(d[k]) * (1.0 + 1e-12);
            int lo = search(xs, nv, x[k] - half, 0), hi = search(xs, nv, x[k] + half, 1);
            c = count_closer(xs + lo, ys + lo, zs + lo, hi - lo, x[k], y[k], z[k], d[k]);
        }
        rank[k] = (double)c / nv;
    }
    free(keys);
    free(sorted);
    return 0;
}

void tcb_pck_curve(const double *d, int n, double (*threshold)(int), int steps, double *pck,
                   double *auc)
{
    double sum = 0.0;
    for (int s = 0; s < steps; s++) {
        double t = threshold(s);
        long long c = 0;
#pragma omp simd reduction(+ : c)
        for (int k = 0; k < n; k++) c += d[k] <= t;
        pck[s] = (double)c / n;
        sum += pck[s];
    }
    *auc = sum / steps;
}

static int check_pred(int nv, const int32_t *pred, tcb_error *err)
{
    if (nv < 1) return tcb_fail(err, TCB_ERR_INPUT, "metrics: frame has no vertices");
    for (int k = 0; k < nv; k++)
        if (pred[k] < 0 || pred[k] >= nv)
            return tcb_fail(err, TCB_ERR_INPUT, "metrics: pred[%d] = %d outside [0, %d)", k,
                            (int)pred[k], nv);
    return TCB_OK;
}

int tcb_pair_vertex_metrics(const float *verts_j, int nv, const int32_t *pred, double *sq,
                            double *rank, tcb_error *err)
{
    int rc = check_pred(nv, pred, err);
    if (rc) return rc;
    double *x = malloc((size_t)nv * 3 * sizeof(double));
    if (!x) return tcb_fail(err, TCB_ERR_NOMEM, "metrics: out of memory");
    double *y = x + nv, *z = y + nv;
    for (int k = 0; k < nv; k++) {
        x[k] = verts_j[3 * k], y[k] = verts_j[3 * k + 1], z[k] = verts_j[3 * k + 2];
    }
    for (int k = 0; k < nv; k++) {
        int p = pred[k];
        double dx = x[p] - x[k], dy = y[p] - y[k], dz = z[p] - z[k];
        sq[k] = dx * dx + dy * dy + dz * dz;
    }
    if (rank && ranks(x, y, z, nv, sq, rank)) rc = tcb_fail(err, TCB_ERR_NOMEM, "metrics: out of memory");
    free(x);
    return rc;
}

void tcb_pair_metrics_summarize(const double *sq, const double *rank, int nv, tcb_pair_metrics *out)
{
    *out = (tcb_pair_metrics){0};
    for (int k = 0; k < nv; k++) {
        tcb_stat_push(&out->sl2, sqrt(sq[k]));
        tcb_stat_push(&out->sl2sq, sq[k]);
        tcb_stat_push(&out->rank, rank[k]);
    }
    tcb_pck_curve(sq, nv, tcb_pck_threshold, TCB_PCK_STEPS, out->pck, &out->auc);
}

int tcb_pair_metrics_compute(const float *verts_j, int nv, const int32_t *pred,
                             tcb_pair_metrics *out, tcb_error *err)
{
    /* Checked first: the buffers are sized by nv. */
    int rc = check_pred(nv, pred, err);
    if (rc) return rc;
    double *buf = malloc((size_t)nv * 2 * sizeof(double));
    if (!buf) return tcb_fail(err, TCB_ERR_NOMEM, "metrics: out of memory");
    rc = tcb_pair_vertex_metrics(verts_j, nv, pred, buf, buf + nv, err);
    if (!rc) tcb_pair_metrics_summarize(buf, buf + nv, nv, out);
    free(buf);
    return rc;
}
