/* Marching tetrahedra in kaolin's order (neural/marching_tets.h). */
#include "neural/marching_tets.h"

#include <stdlib.h>
#include <string.h>

/* A tet's six edges as pairs of its corners (kaolin's base_tet_edges). */
static const int TET_EDGES[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};

/* Per occupancy code Σ occupied_i · 2^i: the triangles, as local edges. */
static const int N_TRIANGLES[16] = {0, 1, 1, 2, 1, 2, 2, 1, 1, 2, 2, 1, 2, 1, 1, 0};
static const int TRIANGLES[16][6] = {
    {0}, {1, 0, 2}, {4, 0, 3}, {1, 4, 2, 1, 3, 4}, {3, 1, 5}, {2, 3, 0, 2, 5, 3},
    {1, 4, 0, 1, 5, 4}, {4, 2, 5}, {4, 5, 2}, {4, 1, 0, 4, 5, 1}, {3, 2, 0, 3, 5, 2},
    {1, 3, 5}, {4, 1, 2, 4, 3, 1}, {3, 0, 4}, {2, 0, 1}, {0}};

void tcb_mt_surface_free(tcb_mt_surface *s)
{
    free(s->verts), free(s->faces), free(s->edges);
    memset(s, 0, sizeof *s);
}

static int tet_code(const float *s, const int32_t *t)
{
    int code = 0;
    for (int k = 0; k < 4; k++) code |= (s[t[k]] > 0.0f) << k;
    return code;
}

static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

static uint64_t edge_key(int32_t a, int32_t b)
{
    return a < b ? (uint64_t)a << 32 | (uint32_t)b : (uint64_t)b << 32 | (uint32_t)a;
}

/* The surface vertex of crossing edge (a, b), as kaolin computes it in
 * float: the weights (−s_b, s_a)/(s_a − s_b) applied to (x_a, x_b). */
static void edge_vertex(const float *x, const float *s, int32_t a, int32_t b, float *v)
{
    float den = s[a] - s[b];
    float wa = -s[b] / den, wb = s[a] / den;
    for (int d = 0; d < 3; d++) v[d] = x[3 * (size_t)a + d] * wa + x[3 * (size_t)b + d] * wb;
}

/* The sorted unique crossing edges of the crossing tets into *keys;
 * code[t] is tet t's occupancy code. */
static int crossing_edges(const float *s, const int32_t *tets, const uint8_t *code, int nt, uint64_t **keys, int *n,
                          tcb_error *err)
{
    size_t cap = 0, m = 0;
    for (int t = 0; t < nt; t++) cap += N_TRIANGLES[code[t]] ? 6 : 0;
    *keys = malloc((cap ? cap : 1) * sizeof **keys);
    if (!*keys) return tcb_fail(err, TCB_ERR_NOMEM, "marching tets: out of memory for %zu edges", cap);
    for (int t = 0; t < nt; t++) {
        const int32_t *q = tets + 4 * (size_t)t;
        if (!N_TRIANGLES[code[t]]) continue;
        for (int e = 0; e < 6; e++) {
            int32_t a = q[TET_EDGES[e][0]], b = q[TET_EDGES[e][1]];
            if ((s[a] > 0.0f) != (s[b] > 0.0f)) (*keys)[m++] = edge_key(a, b);
        }
    }
    qsort(*keys, m, sizeof **keys, cmp_u64);
    size_t u = 0;
    for (size_t i = 0; i < m; i++)
        if (u == 0 || (*keys)[i] != (*keys)[u - 1]) (*keys)[u++] = (*keys)[i];
    *n = (int)u;
    return TCB_OK;
}

static int32_t vertex_of(const uint64_t *keys, int n, uint64_t key)
{
    const uint64_t *hit = bsearch(&key, keys, (size_t)n, sizeof key, cmp_u64);
    return (int32_t)(hit - keys);
}

/* The faces of the tets with `count` triangles, in tet order, from faces[at]. */
static int add_faces(const int32_t *tets, const uint8_t *code, int nt, const uint64_t *keys, int nk, int count,
                     int32_t *faces, int at)
{
    for (int t = 0; t < nt; t++) {
        const int32_t *q = tets + 4 * (size_t)t;
        if (N_TRIANGLES[code[t]] != count) continue;
        for (int c = 0; c < 3 * count; c++) {
            const int *e = TET_EDGES[TRIANGLES[code[t]][c]];
            faces[3 * (size_t)at + c] = vertex_of(keys, nk, edge_key(q[e[0]], q[e[1]]));
        }
        at += count;
    }
    return at;
}

int tcb_marching_tets_forward(const float *x, const float *s, int nv, const int32_t *tets, int nt,
                              tcb_mt_surface *out, tcb_error *err)
{
    memset(out, 0, sizeof *out);
    for (size_t i = 0; i < (size_t)nt * 4; i++)
        if (tets[i] < 0 || tets[i] >= nv)
            return tcb_fail(err, TCB_ERR_INPUT, "marching tets: tet %zu names vertex %d of %d", i / 4, tets[i], nv);
    /* Each tet's occupancy code once: the passes below all read it. */
    uint8_t *code = malloc((size_t)(nt > 0 ? nt : 1));
    if (!code) return tcb_fail(err, TCB_ERR_NOMEM, "marching tets: out of memory for %d tets", nt);
    size_t nf = 0;
    for (int t = 0; t < nt; t++) {
        code[t] = (uint8_t)tet_code(s, tets + 4 * (size_t)t);
        nf += (size_t)N_TRIANGLES[code[t]];
    }
    uint64_t *keys = NULL;
    int nk = 0, rc = crossing_edges(s, tets, code, nt, &keys, &nk, err);
    if (!rc) {
        out->verts = malloc(((size_t)nk * 3 + 1) * sizeof *out->verts);
        out->edges = malloc(((size_t)nk * 2 + 1) * sizeof *out->edges);
        out->faces = malloc((nf * 3 + 1) * sizeof *out->faces);
        if (!out->verts || !out->edges || !out->faces)
            rc = tcb_fail(err, TCB_ERR_NOMEM, "marching tets: out of memory for %zu faces", nf);
    }
    for (int i = 0; !rc && i < nk; i++) {
        int32_t a = (int32_t)(keys[i] >> 32), b = (int32_t)(keys[i] & 0xffffffffu);
        out->edges[2 * i] = a, out->edges[2 * i + 1] = b;
        edge_vertex(x, s, a, b, out->verts + 3 * (size_t)i);
    }
    if (!rc) add_faces(tets, code, nt, keys, nk, 2, out->faces, add_faces(tets, code, nt, keys, nk, 1, out->faces, 0));
    free(keys), free(code);
    if (rc) {
        tcb_mt_surface_free(out);
        return rc;
    }
    out->n_verts = nk, out->n_faces = (int)nf;
    return TCB_OK;
}

void tcb_marching_tets_backward(const float *x, const float *s, const tcb_mt_surface *surf,
                                const float *dverts, float *dx, float *ds)
{
    for (int i = 0; i < surf->n_verts; i++) {
        int32_t a = surf->edges[2 * i], b = surf->edges[2 * i + 1];
        double den = (double)s[a] - s[b];
        const float *g = dverts + 3 * (size_t)i, *v = surf->verts + 3 * (size_t)i;
        double ga = 0, gb = 0;
        for (int d = 0; d < 3; d++) {
            dx[3 * (size_t)a + d] += (float)(g[d] * (-s[b] / den));
            dx[3 * (size_t)b + d] += (float)(g[d] * (s[a] / den));
            ga += g[d] * (x[3 * (size_t)b + d] - (double)v[d]);
            gb += g[d] * ((double)v[d] - x[3 * (size_t)a + d]);
        }
        ds[a] += (float)(ga / den);
        ds[b] += (float)(gb / den);
    }
}
