/* tcb/locate.h: closest surface points by face and barycentric weights. */
#include "tcb/locate.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "tcb/geometry.h"
#include "tcb/nn.h"

static double dot3(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

static void sub3(const double *a, const double *b, double *out)
{
    for (int d = 0; d < 3; d++) out[d] = a[d] - b[d];
}

/* Squared distance from p to the point with weights w of triangle t. */
static double dist2_at(const double *p, const double t[3][3], const double *w)
{
    double e[3];
    for (int d = 0; d < 3; d++) e[d] = p[d] - (w[0] * t[0][d] + w[1] * t[1][d] + w[2] * t[2][d]);
    return dot3(e, e);
}

/* The point at weight 1 − s on vertex i and s on vertex j (s = 0: vertex i). */
static double edge_at(const double *p, const double t[3][3], int i, int j, double s, double *w)
{
    w[0] = w[1] = w[2] = 0;
    w[i] = 1 - s;
    w[j] = s;
    return dist2_at(p, t, w);
}

/* Closest point of segment t[i]–t[j]. */
static double closest_on_edge(const double *p, const double t[3][3], int i, int j, double *w)
{
    double e[3], q[3];
    sub3(t[j], t[i], e);
    sub3(p, t[i], q);
    double len2 = dot3(e, e);
    return edge_at(p, t, i, j, len2 > 0 ? fmin(1.0, fmax(0.0, dot3(q, e) / len2)) : 0.0, w);
}

/* A triangle of zero area: its closest point lies on one of its edges. */
static double closest_degenerate(const double *p, const double t[3][3], double *w)
{
    double best = INFINITY, cand[3];
    for (int k = 0; k < 3; k++) {
        double d2 = closest_on_edge(p, t, k, (k + 1) % 3, cand);
        if (d2 < best) best = d2, memcpy(w, cand, sizeof cand);
    }
    return best;
}

/* The closest point of triangle t to p by the Voronoi regions of its
 * vertices, edges and face (Ericson, Real-Time Collision Detection §5.1.5):
 * weights w, squared distance returned. */
static double closest_on_triangle(const double *p, const double t[3][3], double *w)
{
    double ab[3], ac[3], ap[3], bp[3], cp[3];
    sub3(t[1], t[0], ab);
    sub3(t[2], t[0], ac);
    sub3(p, t[0], ap);
    double d1 = dot3(ab, ap), d2 = dot3(ac, ap);
    if (d1 <= 0 && d2 <= 0) return edge_at(p, t, 0, 1, 0, w); /* vertex a */
    sub3(p, t[1], bp);
    double d3 = dot3(ab, bp), d4 = dot3(ac, bp), vc = d1 * d4 - d3 * d2;
    if (d3 >= 0 && d4 <= d3) return edge_at(p, t, 1, 0, 0, w); /* vertex b */
    if (vc <= 0 && d1 >= 0 && d3 <= 0 && d1 - d3 > 0) return edge_at(p, t, 0, 1, d1 / (d1 - d3), w);
    sub3(p, t[2], cp);
    double d5 = dot3(ab, cp), d6 = dot3(ac, cp), vb = d5 * d2 - d1 * d6, va = d3 * d6 - d5 * d4;
    if (d6 >= 0 && d5 <= d6) return edge_at(p, t, 2, 0, 0, w); /* vertex c */
    if (vb <= 0 && d2 >= 0 && d6 <= 0 && d2 - d6 > 0) return edge_at(p, t, 0, 2, d2 / (d2 - d6), w);
    double e4 = d4 - d3, e5 = d5 - d6;
    if (va <= 0 && e4 >= 0 && e5 >= 0 && e4 + e5 > 0) return edge_at(p, t, 1, 2, e4 / (e4 + e5), w);
    /* The face's interior. On a (nearly) degenerate triangle rounding can
     * land here with weights outside [0, 1]: its edges answer instead. */
    double sum = va + vb + vc;
    if (!(sum > 0) || va < 0 || vb < 0 || vc < 0) return closest_degenerate(p, t, w);
    w[0] = va / sum;
    w[1] = vb / sum;
    w[2] = vc / sum;
    return dist2_at(p, t, w);
}

static void load_triangle(const float *verts, const int32_t *face, double t[3][3])
{
    for (int k = 0; k < 3; k++)
        for (int d = 0; d < 3; d++) t[k][d] = verts[3 * face[k] + d];
}

/* Face centroids (float, for the k-NN index) and the largest distance of a
 * vertex from its face's centroid. */
static double centroids(const float *verts, const int32_t *faces, int nf, float *cen)
{
    double radius = 0;
    for (int f = 0; f < nf; f++) {
        double t[3][3], c[3];
        load_triangle(verts, faces + 3 * f, t);
        for (int d = 0; d < 3; d++) c[d] = (t[0][d] + t[1][d] + t[2][d]) / 3, cen[3 * f + d] = (float)c[d];
        for (int k = 0; k < 3; k++) {
            double e[3];
            sub3(t[k], c, e);
            radius = fmax(radius, sqrt(dot3(e, e)));
        }
    }
    return radius;
}

typedef struct search {
    const float *verts;
    const int32_t *faces;
    const tcb_nn *index; /* over the face centroids */
    int nf;
    double radius;       /* largest vertex-to-centroid distance */
    double extent;       /* largest vertex coordinate magnitude */
    int32_t *idx;        /* [nf] k-NN scratch */
    float *d2;           /* [nf] */
} search;

/* One query: the k nearest centroids, k doubled until the k-th is farther
 * than the best distance plus the radius (every face beyond is then
 * farther than the best), or k covers every face. */
static int locate_one(const search *s, const float *query, tcb_surface_point *out, float *dist2,
                      tcb_error *err)
{
    double p[3] = {query[0], query[1], query[2]}, best = INFINITY, w[3] = {0, 0, 0}, bw[3] = {1, 0, 0};
    int32_t best_face = 0;
    for (int k = s->nf < 16 ? s->nf : 16;; k = 2 * k < s->nf ? 2 * k : s->nf) {
        int rc = tcb_nn_queryk(s->index, query, 1, k, s->idx, s->d2, err);
        if (rc) return rc;
        for (int j = 0; j < k; j++) {
            double t[3][3];
            load_triangle(s->verts, s->faces + 3 * s->idx[j], t);
            double d2 = closest_on_triangle(p, t, w);
            if (d2 < best || (d2 == best && s->idx[j] < best_face))
                best = d2, best_face = s->idx[j], memcpy(bw, w, sizeof w);
        }
        /* The centroid distances are float: slack for their rounding. */
        double mag = fmax(fabs(p[0]), fmax(fabs(p[1]), fabs(p[2]))) + s->extent;
        double bound = sqrt(best) + s->radius + 1e-5 * mag;
        if (k == s->nf || sqrt((double)s->d2[k - 1]) > bound) break;
    }
    out->face = best_face;
    for (int d = 0; d < 3; d++) out->bary[d] = (float)bw[d];
    if (dist2) *dist2 = (float)best;
    return TCB_OK;
}

static int check_input(const float *verts, int nv, const int32_t *faces, int nf, const float *queries, int nq,
                       tcb_error *err)
{
    if (!verts || !faces || nv < 3 || nf < 1)
        return tcb_fail(err, TCB_ERR_INPUT, "locate: the mesh is empty (%d vertices, %d faces)", nv, nf);
    if (nq < 0 || (nq > 0 && !queries)) return tcb_fail(err, TCB_ERR_INPUT, "locate: %d queries", nq);
    for (int i = 0; i < 3 * nf; i++)
        if (faces[i] < 0 || faces[i] >= nv)
            return tcb_fail(err, TCB_ERR_INPUT, "locate: face %d names vertex %d of %d", i / 3, faces[i], nv);
    if (!tcb_all_finite(verts, (size_t)3 * nv))
        return tcb_fail(err, TCB_ERR_NUMERIC, "locate: a vertex coordinate is not finite");
    if (!tcb_all_finite(queries, (size_t)3 * nq))
        return tcb_fail(err, TCB_ERR_NUMERIC, "locate: a query coordinate is not finite");
    return TCB_OK;
}

int tcb_mesh_locate(const float *verts, int nv, const int32_t *faces, int nf, const float *queries, int nq,
                    tcb_surface_point *out, float *dist2, tcb_error *err)
{
    int rc = check_input(verts, nv, faces, nf, queries, nq, err);
    if (rc || nq == 0) return rc;
    search s = {.verts = verts, .faces = faces, .nf = nf};
    float *cen = malloc((size_t)3 * nf * sizeof *cen);
    s.idx = malloc((size_t)nf * sizeof *s.idx);
    s.d2 = malloc((size_t)nf * sizeof *s.d2);
    tcb_nn *index = NULL;
    if (!cen || !s.idx || !s.d2) {
        rc = tcb_fail(err, TCB_ERR_NOMEM, "locate: out of memory for %d faces", nf);
        goto done;
    }
    s.radius = centroids(verts, faces, nf, cen);
    for (int i = 0; i < 3 * nv; i++) s.extent = fmax(s.extent, fabs(verts[i]));
    if ((rc = tcb_nn_build(cen, nf, &index, err))) goto done;
    s.index = index;
    for (int q = 0; q < nq && !rc; q++) rc = locate_one(&s, queries + 3 * q, out + q, dist2 ? dist2 + q : NULL, err);
done:
    tcb_nn_free(index);
    free(cen);
    free(s.idx);
    free(s.d2);
    return rc;
}

void tcb_surface_points(const float *verts, const int32_t *faces, const tcb_surface_point *loc, int n, float *out)
{
    for (int q = 0; q < n; q++) {
        const int32_t *f = faces + 3 * loc[q].face;
        for (int d = 0; d < 3; d++)
            out[3 * q + d] = loc[q].bary[0] * verts[3 * f[0] + d] + loc[q].bary[1] * verts[3 * f[1] + d] +
                             loc[q].bary[2] * verts[3 * f[2] + d];
    }
}
