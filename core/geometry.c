/* Triangle-mesh geometry. Everything accumulates in double: a 20k-face
 * mesh summed in float loses ~4 digits of its area. */
#include "tcb/geometry.h"

#include <math.h>
#include <stdlib.h>

/* (b − a) × (c − a), whose length is twice the triangle's area. */
static void tri_cross(const float *a, const float *b, const float *c, double n[3])
{
    double u[3] = {(double)b[0] - a[0], (double)b[1] - a[1], (double)b[2] - a[2]};
    double v[3] = {(double)c[0] - a[0], (double)c[1] - a[1], (double)c[2] - a[2]};
    n[0] = u[1] * v[2] - u[2] * v[1];
    n[1] = u[2] * v[0] - u[0] * v[2];
    n[2] = u[0] * v[1] - u[1] * v[0];
}

int tcb_all_finite(const float *x, size_t n)
{
    for (size_t k = 0; k < n; k++)
        if (!isfinite(x[k])) return 0;
    return 1;
}

int tcb_all_finite_d(const double *x, size_t n)
{
    for (size_t k = 0; k < n; k++)
        if (!isfinite(x[k])) return 0;
    return 1;
}

void tcb_bbox(const float *points, size_t n, double box[6])
{
    for (int d = 0; d < 3; d++) box[d] = INFINITY, box[3 + d] = -INFINITY;
    for (size_t k = 0; k < n; k++)
        for (int d = 0; d < 3; d++) {
            double x = points[3 * k + d];
            box[d] = fmin(box[d], x), box[3 + d] = fmax(box[3 + d], x);
        }
}

double tcb_bbox_diag(const double box[6])
{
    double d2 = 0;
    for (int d = 0; d < 3; d++) d2 += (box[3 + d] - box[d]) * (box[3 + d] - box[d]);
    return sqrt(d2);
}

double tcb_triangle_area(const float *a, const float *b, const float *c)
{
    double n[3];
    tri_cross(a, b, c, n);
    return 0.5 * sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
}

static double face_area(const float *verts, const int32_t *f)
{
    return tcb_triangle_area(verts + 3 * (size_t)f[0], verts + 3 * (size_t)f[1],
                             verts + 3 * (size_t)f[2]);
}

double tcb_mesh_area(const float *verts, const int32_t *faces, int nf)
{
    double total = 0.0;
    for (int i = 0; i < nf; i++) total += face_area(verts, faces + 3 * (size_t)i);
    return total;
}

void tcb_surface_centroid(const float *verts, const int32_t *faces, int nf, double c[3])
{
    /* Each triangle contributes its own centroid weighted by its area; a
     * zero-area mesh falls back to the plain mean of the face corners. */
    double acc[3] = {0, 0, 0}, plain[3] = {0, 0, 0}, total = 0.0;
    for (int i = 0; i < nf; i++) {
        const int32_t *f = faces + 3 * (size_t)i;
        double w = face_area(verts, f);
        for (int k = 0; k < 3; k++) {
            const float *p = verts + 3 * (size_t)f[k];
            for (int d = 0; d < 3; d++) {
                acc[d] += w * p[d];
                plain[d] += p[d];
            }
        }
        total += w;
    }
    for (int d = 0; d < 3; d++)
        c[d] = total > 0.0 ? acc[d] / (3.0 * total) : nf > 0 ? plain[d] / (3.0 * nf) : 0.0;
}

void tcb_vertex_normals(const float *verts, int nv, const int32_t *faces, int nf,
                        float *normals)
{
    for (size_t i = 0; i < 3 * (size_t)nv; i++) normals[i] = 0.0f;
    /* The unnormalized cross product already carries the area weight. */
    for (int i = 0; i < nf; i++) {
        const int32_t *f = faces + 3 * (size_t)i;
        double n[3];
        tri_cross(verts + 3 * (size_t)f[0], verts + 3 * (size_t)f[1], verts + 3 * (size_t)f[2], n);
        for (int k = 0; k < 3; k++)
            for (int d = 0; d < 3; d++) normals[3 * (size_t)f[k] + d] += (float)n[d];
    }
    for (int v = 0; v < nv; v++) {
        float *n = normals + 3 * (size_t)v;
        double len = sqrt((double)n[0] * n[0] + (double)n[1] * n[1] + (double)n[2] * n[2]);
        for (int d = 0; d < 3; d++) n[d] = len > 0.0 ? (float)(n[d] / len) : 0.0f;
    }
}

/* First face whose cumulative area exceeds r; cdf is [nf], non-decreasing,
 * so zero-area faces (cdf[i] == cdf[i-1]) are never returned. */
static int cdf_search(const double *cdf, int nf, double r)
{
    int lo = 0, hi = nf - 1;
    while (lo < hi) {
        int mid = lo + (hi - lo) / 2;
        if (cdf[mid] > r) hi = mid;
        else lo = mid + 1;
    }
    return lo;
}

int tcb_sample_surface(const float *verts, const int32_t *faces, int nf, int n,
                       tcb_rng *rng, float *out, tcb_error *err)
{
    return tcb_sample_surface_faces(verts, faces, nf, n, rng, out, NULL, err);
}

void tcb_face_normal(const float *verts, const int32_t *face, float out[3])
{
    double n[3];
    tri_cross(verts + 3 * (size_t)face[0], verts + 3 * (size_t)face[1], verts + 3 * (size_t)face[2], n);
    double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    for (int d = 0; d < 3; d++) out[d] = len > 0.0 ? (float)(n[d] / len) : 0.0f;
}

int tcb_sample_surface_faces(const float *verts, const int32_t *faces, int nf, int n,
                             tcb_rng *rng, float *out, int32_t *face_of, tcb_error *err)
{
    if (n < 0 || nf <= 0)
        return tcb_fail(err, TCB_ERR_INPUT, "cannot sample %d points from %d faces", n, nf);
    double *cdf = malloc((size_t)nf * sizeof *cdf); /* [nf] running area */
    if (!cdf) return tcb_fail(err, TCB_ERR_NOMEM, "sampling: cannot allocate %d faces", nf);
    double total = 0.0;
    for (int i = 0; i < nf; i++) {
        total += face_area(verts, faces + 3 * (size_t)i);
        cdf[i] = total;
    }
    if (!(total > 0.0) || !isfinite(total)) {
        free(cdf);
        return tcb_fail(err, TCB_ERR_INPUT, "cannot sample a mesh of area %g", total);
    }
    for (int s = 0; s < n; s++) {
        /* u·total can round up to total; keeping r strictly below it means
         * the search always finds a face with cdf > r, i.e. positive area. */
        double r = fmin(tcb_rng_uniform(rng) * total, nextafter(total, 0.0));
        int face = cdf_search(cdf, nf, r);
        if (face_of) face_of[s] = face;
        const int32_t *f = faces + 3 * (size_t)face;
        /* PyTorch3D's barycentrics: uniform over the triangle. */
        double su = sqrt(tcb_rng_uniform(rng)), v = tcb_rng_uniform(rng);
        double w0 = 1.0 - su, w1 = su * (1.0 - v), w2 = su * v;
        const float *a = verts + 3 * (size_t)f[0], *b = verts + 3 * (size_t)f[1],
                    *c = verts + 3 * (size_t)f[2];
        for (int d = 0; d < 3; d++) out[3 * (size_t)s + d] = (float)(w0 * a[d] + w1 * b[d] + w2 * c[d]);
    }
    free(cdf);
    return TCB_OK;
}

int tcb_farthest_points(const float *pts, int n, int k, int start, int32_t *idx, tcb_error *err)
{
    float *best = malloc((size_t)n * sizeof *best); /* squared distance to the chosen set */
    if (!best) return tcb_fail(err, TCB_ERR_NOMEM, "farthest points: out of memory for %d points", n);
    for (int i = 0; i < n; i++) best[i] = INFINITY;
    int cur = start;
    for (int c = 0; c < k; c++) {
        idx[c] = cur;
        const float *p = pts + 3 * (size_t)cur;
        int next = 0;
        for (int i = 0; i < n; i++) {
            const float *q = pts + 3 * (size_t)i;
            float dx = q[0] - p[0], dy = q[1] - p[1], dz = q[2] - p[2];
            float d = dx * dx + dy * dy + dz * dz;
            if (d < best[i]) best[i] = d;
            if (best[i] > best[next]) next = i;
        }
        cur = next;
    }
    free(best);
    return TCB_OK;
}
