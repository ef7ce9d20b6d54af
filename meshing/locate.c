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

/* Face f's centroid (float, for the k-NN index) and its radius: the
 * largest distance of one of its vertices from the centroid. */
static double centroid_of(const float *verts, const int32_t *face, float *cen)
{
    double t[3][3], c[3], radius = 0;
    load_triangle(verts, face, t);
    for (int d = 0; d < 3; d++) c[d] = (t[0][d] + t[1][d] + t[2][d]) / 3, cen[d] = (float)c[d];
    for (int k = 0; k < 3; k++) {
        double e[3];
        sub3(t[k], c, e);
        radius = fmax(radius, sqrt(dot3(e, e)));
    }
    return radius;
}

/* Faces are searched by the distance of their centroids, and a face whose
 * centroid lies beyond the best distance plus its radius cannot be closer.
 * One radius for all faces would let a single sliver widen every query's
 * search to thousands of faces; so faces are grouped by radius, class c
 * holding those with radius in (r_max / 2^(c+1), r_max / 2^c] (the last
 * class everything smaller), each with its own index and bound. */
enum { N_CLASSES = 24 };

typedef struct face_class {
    tcb_nn *index;   /* over the class's centroids; NULL when empty */
    int32_t *face;   /* [n]: the class's k-th centroid is face face[k]'s */
    int n;
    double radius;   /* the largest radius in the class */
} face_class;

typedef struct search {
    const float *verts;
    const int32_t *faces;
    face_class cls[N_CLASSES];
    double extent;   /* largest vertex coordinate magnitude */
    int32_t *idx;    /* [nf] k-NN scratch */
    float *d2;       /* [nf] */
} search;

static int class_of(double radius, double r_max)
{
    int c = 0;
    while (c < N_CLASSES - 1 && radius <= r_max / (double)(2 << c)) c++;
    return c;
}

/* The classes and their indices; s->idx and s->d2 allocated for nf. */
static int build_classes(search *s, int nf, tcb_error *err)
{
    float *cen = malloc((size_t)3 * nf * sizeof *cen), *class_cen = malloc((size_t)3 * nf * sizeof *class_cen);
    double *radius = malloc((size_t)nf * sizeof *radius), r_max = 0;
    int8_t *c_of = malloc((size_t)nf);
    s->idx = malloc((size_t)nf * sizeof *s->idx);
    s->d2 = malloc((size_t)nf * sizeof *s->d2);
    int rc = TCB_OK;
    if (!cen || !class_cen || !radius || !c_of || !s->idx || !s->d2) {
        rc = tcb_fail(err, TCB_ERR_NOMEM, "locate: out of memory for %d faces", nf);
        goto done;
    }
    for (int f = 0; f < nf; f++) r_max = fmax(r_max, radius[f] = centroid_of(s->verts, s->faces + 3 * f, cen + 3 * f));
    for (int f = 0; f < nf; f++) s->cls[c_of[f] = (int8_t)class_of(radius[f], r_max)].n++;
    for (int c = 0; c < N_CLASSES && !rc; c++) {
        face_class *k = &s->cls[c];
        if (!k->n) continue;
        if (!(k->face = malloc((size_t)k->n * sizeof *k->face))) {
            rc = tcb_fail(err, TCB_ERR_NOMEM, "locate: out of memory for %d faces", nf);
            break;
        }
        int n = 0;
        for (int f = 0; f < nf; f++)
            if (c_of[f] == c) {
                k->face[n] = f, k->radius = fmax(k->radius, radius[f]);
                memcpy(class_cen + 3 * n++, cen + 3 * f, 3 * sizeof *cen);
            }
        rc = tcb_nn_build(class_cen, n, &k->index, err);
    }
done:
    free(cen), free(class_cen), free(radius), free(c_of);
    return rc;
}

static void free_search(search *s)
{
    for (int c = 0; c < N_CLASSES; c++) tcb_nn_free(s->cls[c].index), free(s->cls[c].face);
    free(s->idx), free(s->d2);
}

/* Within one class: the k nearest centroids, k doubled until the k-th is
 * farther than the best distance so far plus the class's radius (every
 * face of the class beyond is then farther than the best), or k covers the
 * class. Exact ties go to the lowest face index, whatever the order the
 * faces are met in. */
static int search_class(const search *s, const face_class *k, const float *query, double *best, int32_t *best_face,
                        double *bw, tcb_error *err)
{
    double p[3] = {query[0], query[1], query[2]}, w[3] = {0, 0, 0};
    /* The centroid distances are float: slack for their rounding. */
    double slack = 1e-5 * (fmax(fabs(p[0]), fmax(fabs(p[1]), fabs(p[2]))) + s->extent);
    for (int n = k->n < 16 ? k->n : 16;; n = 2 * n < k->n ? 2 * n : k->n) {
        int rc = tcb_nn_queryk(k->index, query, 1, n, s->idx, s->d2, err);
        if (rc) return rc;
        for (int j = 0; j < n; j++) {
            int32_t f = k->face[s->idx[j]];
            double t[3][3];
            load_triangle(s->verts, s->faces + 3 * f, t);
            double d2 = closest_on_triangle(p, t, w);
            if (d2 < *best || (d2 == *best && f < *best_face)) *best = d2, *best_face = f, memcpy(bw, w, sizeof w);
        }
        if (n == k->n || sqrt((double)s->d2[n - 1]) > sqrt(*best) + k->radius + slack) return TCB_OK;
    }
}

/* One query: the classes from the smallest faces (most of the mesh, and
 * the tightest bound) to the largest, each pruned by the best so far. */
static int locate_one(const search *s, const float *query, tcb_surface_point *out, float *dist2,
                      tcb_error *err)
{
    double best = INFINITY, bw[3] = {1, 0, 0};
    int32_t best_face = 0;
    for (int c = N_CLASSES - 1; c >= 0; c--) {
        if (!s->cls[c].n) continue;
        int rc = search_class(s, &s->cls[c], query, &best, &best_face, bw, err);
        if (rc) return rc;
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
    search s = {.verts = verts, .faces = faces};
    for (int i = 0; i < 3 * nv; i++) s.extent = fmax(s.extent, fabs(verts[i]));
    rc = build_classes(&s, nf, err);
    for (int q = 0; q < nq && !rc; q++) rc = locate_one(&s, queries + 3 * q, out + q, dist2 ? dist2 + q : NULL, err);
    free_search(&s);
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
