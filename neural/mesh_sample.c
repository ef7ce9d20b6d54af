#include "neural/mesh_sample.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "tcb/rng.h"

/* c = (b − a) × (c − b) of face f, in double. */
static void face_cross(const float *verts, const int32_t *f, double *c, double *e1, double *e2)
{
    const float *a = verts + 3 * f[0], *b = verts + 3 * f[1], *q = verts + 3 * f[2];
    for (int d = 0; d < 3; d++) e1[d] = (double)b[d] - a[d], e2[d] = (double)q[d] - b[d];
    c[0] = e1[1] * e2[2] - e1[2] * e2[1];
    c[1] = e1[2] * e2[0] - e1[0] * e2[2];
    c[2] = e1[0] * e2[1] - e1[1] * e2[0];
}

static double norm3(const double *v) { return sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

/* The first index whose cumulative weight exceeds u·total. */
static int32_t pick(const double *cdf, int nf, double u)
{
    double target = u * cdf[nf - 1];
    int lo = 0, hi = nf - 1;
    while (lo < hi) {
        int mid = lo + (hi - lo) / 2;
        if (cdf[mid] > target) hi = mid;
        else lo = mid + 1;
    }
    return lo;
}

int tcb_mesh_sample_draw(const float *verts, const int32_t *faces, int nf, int m, struct tcb_rng *rng,
                         tcb_mesh_draw *draws, tcb_error *err)
{
    if (nf < 1) return tcb_fail(err, TCB_ERR_NUMERIC, "mesh sampling: the surface has no faces");
    double *cdf = malloc((size_t)nf * sizeof *cdf);
    if (!cdf) return tcb_fail(err, TCB_ERR_NOMEM, "mesh sampling: out of memory for %d faces", nf);
    double total = 0, c[3], e1[3], e2[3];
    for (int f = 0; f < nf; f++) {
        face_cross(verts, faces + 3 * f, c, e1, e2);
        cdf[f] = total += 0.5 * norm3(c);
    }
    if (!(total > 0) || !isfinite(total)) {
        free(cdf);
        return tcb_fail(err, TCB_ERR_NUMERIC, "mesh sampling: the surface's area is %g", total);
    }
    for (int i = 0; i < m; i++) {
        draws[i].face = pick(cdf, nf, tcb_rng_uniform(rng));
        double su = sqrt(tcb_rng_uniform(rng)), v = tcb_rng_uniform(rng);
        draws[i].w[0] = (float)(1 - su), draws[i].w[1] = (float)(su * (1 - v)), draws[i].w[2] = (float)(su * v);
    }
    free(cdf);
    return TCB_OK;
}

void tcb_mesh_sample_forward(const float *verts, const int32_t *faces, const tcb_mesh_draw *draws, int m, float *pts,
                             float *normals)
{
    for (int i = 0; i < m; i++) {
        const int32_t *f = faces + 3 * draws[i].face;
        const float *w = draws[i].w;
        for (int d = 0; d < 3; d++)
            pts[3 * i + d] = w[0] * verts[3 * f[0] + d] + w[1] * verts[3 * f[1] + d] + w[2] * verts[3 * f[2] + d];
        if (!normals) continue;
        double c[3], e1[3], e2[3];
        face_cross(verts, f, c, e1, e2);
        double len = fmax(norm3(c), FLT_EPSILON);
        for (int d = 0; d < 3; d++) normals[3 * i + d] = (float)(c[d] / len);
    }
}

/* dverts of face f from g = ∂L/∂n, through n = c / max(|c|, ε). */
static void normal_backward(const float *verts, const int32_t *f, const float *g, float *dverts)
{
    double c[3], e1[3], e2[3];
    face_cross(verts, f, c, e1, e2);
    double len = norm3(c), gc[3];
    if (len > FLT_EPSILON) {
        double ng = (c[0] * g[0] + c[1] * g[1] + c[2] * g[2]) / (len * len);
        for (int d = 0; d < 3; d++) gc[d] = (g[d] - c[d] * ng) / len;
    } else {
        for (int d = 0; d < 3; d++) gc[d] = g[d] / FLT_EPSILON;
    }
    double de1[3] = {e2[1] * gc[2] - e2[2] * gc[1], e2[2] * gc[0] - e2[0] * gc[2], e2[0] * gc[1] - e2[1] * gc[0]};
    double de2[3] = {gc[1] * e1[2] - gc[2] * e1[1], gc[2] * e1[0] - gc[0] * e1[2], gc[0] * e1[1] - gc[1] * e1[0]};
    for (int d = 0; d < 3; d++) {
        dverts[3 * f[0] + d] -= (float)de1[d];
        dverts[3 * f[1] + d] += (float)(de1[d] - de2[d]);
        dverts[3 * f[2] + d] += (float)de2[d];
    }
}

void tcb_mesh_sample_backward(const float *verts, const int32_t *faces, int nf, const tcb_mesh_draw *draws, int m,
                              const float *dpts, const float *dnormals, float *face_grad, float *dverts)
{
    if (dpts)
        for (int i = 0; i < m; i++) {
            const int32_t *f = faces + 3 * draws[i].face;
            for (int k = 0; k < 3; k++)
                for (int d = 0; d < 3; d++) dverts[3 * f[k] + d] += draws[i].w[k] * dpts[3 * i + d];
        }
    if (!dnormals) return;
    memset(face_grad, 0, (size_t)nf * 3 * sizeof *face_grad);
    for (int i = 0; i < m; i++)
        for (int d = 0; d < 3; d++) face_grad[3 * draws[i].face + d] += dnormals[3 * i + d];
    for (int f = 0; f < nf; f++) {
        const float *g = face_grad + 3 * f;
        if (g[0] != 0 || g[1] != 0 || g[2] != 0) normal_backward(verts, faces + 3 * f, g, dverts);
    }
}
