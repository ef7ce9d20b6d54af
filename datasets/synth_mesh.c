/* Rest surface of a synthetic body: marching tetrahedra on a body-centred
 * cubic lattice, vertices welded by lattice edge, then a few rounds of
 * Laplacian relaxation projected back onto the implicit surface.
 *
 * Why BCC: its tetrahedra (two neighbouring cube centres + one edge of their
 * shared face) are mapped onto each other by the x → −x mirror when the
 * lattice is centred on x = 0, so a mirror-symmetric field gives a
 * mirror-symmetric mesh, and marching tetrahedra needs no case tables.
 * The surface separating negative from non-negative lattice values is a
 * closed 2-manifold by construction (the zero set of a piecewise-linear
 * function at a regular value); the only extra vertices are the centres of
 * quads whose two diagonals tie, which keeps that true. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "datasets/synth_internal.h"

#define RELAX_ROUNDS  5
#define RELAX_STEP    0.5f
#define PROJECT_STEPS 3
/* Crossing parameters are kept inside [T_MIN, 1 − T_MIN] of a lattice edge
 * so that no triangle of the raw mesh collapses onto a lattice node. */
#define T_MIN 0.1f

/* ---- lattice: doubled integer coordinates, corners all even, centres all odd */

typedef struct lattice {
    int ni, nj, nk; /* I ∈ [−ni, ni], J ∈ [0, nj], K ∈ [0, nk] */
    int dy, dz;     /* strides: id = ((I + ni)·dy + J)·dz + K */
    double half;    /* half the cell size */
    double y0, z0;
    float *field; /* [2ni+1][nj+1][nk+1], set on lattice nodes only */
} lattice;

static int64_t node_id(const lattice *L, int I, int J, int K)
{
    return ((int64_t)(I + L->ni) * L->dy + J) * L->dz + K;
}

static void node_pos(const lattice *L, int I, int J, int K, float p[3])
{
    /* I·half and (−I)·half differ only in sign: the lattice is exactly
     * mirror-symmetric. */
    p[0] = (float)(I * L->half);
    p[1] = (float)(L->y0 + J * L->half);
    p[2] = (float)(L->z0 + K * L->half);
}

static int lattice_init(lattice *L, const tcb_synth_body *b)
{
    float lo[3], hi[3];
    tcb_synth_body_bounds(b, b->blend + 2.0f * b->cell, lo, hi);
    double h = b->cell;
    L->half = 0.5 * h;
    L->ni = 2 * (int)ceil(fmax(fabs(lo[0]), fabs(hi[0])) / h);
    L->nj = 2 * (int)ceil((hi[1] - lo[1]) / h);
    L->nk = 2 * (int)ceil((hi[2] - lo[2]) / h);
    L->y0 = lo[1];
    L->z0 = lo[2];
    L->dz = L->nk + 1;
    L->dy = L->nj + 1;
    size_t n = (size_t)(2 * L->ni + 1) * (size_t)L->dy * (size_t)L->dz;
    L->field = malloc(n * sizeof *L->field);
    if (!L->field) return TCB_ERR_NOMEM;
    for (int I = -L->ni; I <= L->ni; I++)
        for (int J = 0; J <= L->nj; J++)
            for (int K = I & 1; K <= L->nk; K += 2) {
                if ((I & 1) != (J & 1)) continue;
                float p[3];
                node_pos(L, I, J, K, p);
                L->field[node_id(L, I, J, K)] = tcb_synth_body_field(b, p);
            }
    return TCB_OK;
}

/* ---- growing arrays and the edge → vertex map -------------------------- */

typedef struct mesh_buf {
    float *v;   /* [nv][3] */
    int32_t *f; /* [nf][3] */
    int nv, nf, cap_v, cap_f;
    uint64_t *key; /* open addressing: edge key + 1 (0 = empty) */
    int32_t *val;
    size_t cap_h; /* power of two */
} mesh_buf;

static int grow(void **p, int *cap, int need, size_t elem)
{
    if (need <= *cap) return TCB_OK;
    int c = *cap ? *cap * 2 : 1024;
    while (c < need) c *= 2;
    void *q = realloc(*p, (size_t)c * elem);
    if (!q) return TCB_ERR_NOMEM;
    *p = q;
    *cap = c;
    return TCB_OK;
}

static size_t hash_slot(const mesh_buf *m, uint64_t key)
{
    uint64_t h = key * 0x9e3779b97f4a7c15ULL;
    return (size_t)(h >> 17) & (m->cap_h - 1);
}

static int hash_rehash(mesh_buf *m)
{
    size_t old = m->cap_h;
    uint64_t *ok = m->key;
    int32_t *ov = m->val;
    m->cap_h = old ? old * 2 : 4096;
    m->key = calloc(m->cap_h, sizeof *m->key);
    m->val = malloc(m->cap_h * sizeof *m->val);
    if (!m->key || !m->val) {
        free(ok);
        free(ov);
        return TCB_ERR_NOMEM;
    }
    for (size_t i = 0; i < old; i++) {
        if (!ok[i]) continue;
        size_t s = hash_slot(m, ok[i]);
        while (m->key[s]) s = (s + 1) & (m->cap_h - 1);
        m->key[s] = ok[i];
        m->val[s] = ov[i];
    }
    free(ok);
    free(ov);
    return TCB_OK;
}

/* Vertex on the lattice edge from inside node `in` to outside node `out`:
 * created at the first request, shared by every tetrahedron on that edge.
 * Ordering the edge inside → outside (not by id) makes the crossing point
 * bit-identical to its mirror image's. Returns the index, or −1 on OOM. */
static int32_t edge_vertex(mesh_buf *m, const lattice *L, const int in[3], const int out[3])
{
    if (2 * (size_t)(m->nv + 1) > m->cap_h && hash_rehash(m)) return -1;
    int64_t a = node_id(L, in[0], in[1], in[2]), c = node_id(L, out[0], out[1], out[2]);
    uint64_t key = ((uint64_t)a << 32 | (uint64_t)c) + 1;
    size_t s = hash_slot(m, key);
    while (m->key[s]) {
        if (m->key[s] == key) return m->val[s];
        s = (s + 1) & (m->cap_h - 1);
    }
    if (grow((void **)&m->v, &m->cap_v, m->nv + 1, 3 * sizeof *m->v)) return -1;
    float fa = L->field[a], fc = L->field[c], pa[3], pc[3];
    node_pos(L, in[0], in[1], in[2], pa);
    node_pos(L, out[0], out[1], out[2], pc);
    float t = fa / (fa - fc);
    t = fminf(fmaxf(t, T_MIN), 1.0f - T_MIN);
    for (int k = 0; k < 3; k++) m->v[3 * (size_t)m->nv + k] = pa[k] + t * (pc[k] - pa[k]);
    m->key[s] = key;
    m->val[s] = m->nv;
    return m->nv++;
}

/* ---- marching tetrahedra ------------------------------------------------ */

static int emit_triangle(mesh_buf *m, int32_t i0, int32_t i1, int32_t i2, const float dir[3])
{
    /* dir points from the inside nodes to the outside ones: the triangle
     * plane separates the two groups, so this orients it outward. */
    if (i0 < 0 || i1 < 0 || i2 < 0) return TCB_ERR_NOMEM;
    if (grow((void **)&m->f, &m->cap_f, m->nf + 1, 3 * sizeof *m->f)) return TCB_ERR_NOMEM;
    const float *a = m->v + 3 * (size_t)i0, *b = m->v + 3 * (size_t)i1, *c = m->v + 3 * (size_t)i2;
    float u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    float w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    float n[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
    int32_t *f = m->f + 3 * (size_t)m->nf++;
    int flip = n[0] * dir[0] + n[1] * dir[1] + n[2] * dir[2] < 0.0f;
    f[0] = i0;
    f[1] = flip ? i2 : i1;
    f[2] = flip ? i1 : i2;
    return TCB_OK;
}

/* Orders the quad diagonals pq and rs by the mirror-invariant key
 * (length², midpoint y, midpoint z): < 0 when pq comes first, 0 on a tie.
 * A quad that is its own mirror image always ties, since the mirror swaps
 * its diagonals. */
static int diagonal_order(const float *p, const float *q, const float *r, const float *s)
{
    float d1 = 0.0f, d2 = 0.0f;
    for (int k = 0; k < 3; k++) {
        d1 += (q[k] - p[k]) * (q[k] - p[k]);
        d2 += (s[k] - r[k]) * (s[k] - r[k]);
    }
    if (d1 != d2) return d1 < d2 ? -1 : 1;
    for (int k = 1; k < 3; k++)
        if (p[k] + q[k] != r[k] + s[k]) return p[k] + q[k] < r[k] + s[k] ? -1 : 1;
    return 0;
}

/* Splits quad q[0..3] (cyclic) into triangles: along the first diagonal by
 * diagonal_order, or, on a tie, as a fan around a new centre vertex so the
 * split stays mirror-symmetric. */
static int emit_quad(mesh_buf *m, const int32_t q[4], const float dir[3])
{
    const float *P[4];
    for (int i = 0; i < 4; i++) P[i] = m->v + 3 * (size_t)q[i];
    int order = diagonal_order(P[0], P[2], P[1], P[3]);
    if (order) {
        int s = order < 0 ? 0 : 1; /* the diagonal runs q[s] – q[s+2] */
        int rc = emit_triangle(m, q[s], q[s + 1], q[(s + 2) & 3], dir);
        return rc ? rc : emit_triangle(m, q[s], q[(s + 2) & 3], q[(s + 3) & 3], dir);
    }
    if (grow((void **)&m->v, &m->cap_v, m->nv + 1, 3 * sizeof *m->v)) return TCB_ERR_NOMEM;
    float *c = m->v + 3 * (size_t)m->nv;
    for (int k = 0; k < 3; k++)
        c[k] = 0.25f * (m->v[3 * (size_t)q[0] + k] + m->v[3 * (size_t)q[1] + k] +
                        m->v[3 * (size_t)q[2] + k] + m->v[3 * (size_t)q[3] + k]);
    int32_t centre = m->nv++;
    for (int i = 0; i < 4; i++) {
        int rc = emit_triangle(m, centre, q[i], q[(i + 1) & 3], dir);
        if (rc) return rc;
    }
    return TCB_OK;
}

static int march_tet(mesh_buf *m, const lattice *L, int node[4][3])
{
    int in[4], out[4], n_in = 0, n_out = 0;
    float c_in[3] = {0.0f, 0.0f, 0.0f}, c_out[3] = {0.0f, 0.0f, 0.0f};
    for (int i = 0; i < 4; i++) {
        float p[3];
        node_pos(L, node[i][0], node[i][1], node[i][2], p);
        int inside = L->field[node_id(L, node[i][0], node[i][1], node[i][2])] < 0.0f;
        if (inside)
            in[n_in++] = i;
        else
            out[n_out++] = i;
        for (int k = 0; k < 3; k++) (inside ? c_in : c_out)[k] += p[k];
    }
    if (n_in == 0 || n_out == 0) return TCB_OK;
    float dir[3]; /* inside centroid → outside centroid */
    for (int k = 0; k < 3; k++) dir[k] = c_out[k] / (float)n_out - c_in[k] / (float)n_in;
    if (n_in == 1 || n_out == 1) {
        int lone = n_in == 1 ? in[0] : out[0], *rest = n_in == 1 ? out : in;
        int32_t v[3];
        for (int i = 0; i < 3; i++)
            v[i] = n_in == 1 ? edge_vertex(m, L, node[lone], node[rest[i]])
                             : edge_vertex(m, L, node[rest[i]], node[lone]);
        return emit_triangle(m, v[0], v[1], v[2], dir);
    }
    /* Two in (a, b), two out (c, d): the quad ac, ad, bd, bc. */
    int32_t q[4] = {
        edge_vertex(m, L, node[in[0]], node[out[0]]), edge_vertex(m, L, node[in[0]], node[out[1]]),
        edge_vertex(m, L, node[in[1]], node[out[1]]), edge_vertex(m, L, node[in[1]], node[out[0]])};
    for (int i = 0; i < 4; i++)
        if (q[i] < 0) return TCB_ERR_NOMEM;
    return emit_quad(m, q, dir);
}

/* Every tetrahedron = two face-adjacent cube centres + one edge of their
 * shared face; 12 per cube. */
static int march_lattice(mesh_buf *m, const lattice *L)
{
    static const int ring[4][2] = {{1, 1}, {-1, 1}, {-1, -1}, {1, -1}};
    int hi[3] = {L->ni, L->nj, L->nk};
    for (int I = -L->ni + 1; I < L->ni; I += 2)
        for (int J = 1; J < L->nj; J += 2)
            for (int K = 1; K < L->nk; K += 2)
                for (int d = 0; d < 3; d++) {
                    int c[3] = {I, J, K};
                    if (c[d] + 2 > hi[d]) continue;
                    int u = (d + 1) % 3, w = (d + 2) % 3;
                    for (int e = 0; e < 4; e++) {
                        int node[4][3];
                        for (int k = 0; k < 3; k++) {
                            node[0][k] = c[k];
                            node[1][k] = c[k] + 2 * (k == d);
                            node[2][k] = node[3][k] = c[k] + (k == d);
                        }
                        node[2][u] += ring[e][0];
                        node[2][w] += ring[e][1];
                        node[3][u] += ring[(e + 1) & 3][0];
                        node[3][w] += ring[(e + 1) & 3][1];
                        int rc = march_tet(m, L, node);
                        if (rc) return rc;
                    }
                }
    return TCB_OK;
}

/* ---- relaxation --------------------------------------------------------- */

/* Newton steps along the numerical gradient onto the zero set. */
static void project(const tcb_synth_body *b, float p[3])
{
    float eps = 0.05f * b->cell;
    for (int it = 0; it < PROJECT_STEPS; it++) {
        float f = tcb_synth_body_field(b, p), g[3], gg = 0.0f;
        for (int k = 0; k < 3; k++) {
            float q[3] = {p[0], p[1], p[2]}, r[3] = {p[0], p[1], p[2]};
            q[k] += eps;
            r[k] -= eps;
            g[k] = (tcb_synth_body_field(b, q) - tcb_synth_body_field(b, r)) / (2.0f * eps);
            gg += g[k] * g[k];
        }
        if (gg < 1e-12f) return;
        for (int k = 0; k < 3; k++) p[k] -= f * g[k] / gg;
    }
}

/* Uniform Laplacian steps, each followed by projection: evens out the
 * slivers marching tetrahedra leaves without leaving the surface. */
static int relax(const tcb_synth_body *b, mesh_buf *m)
{
    size_t n3 = 3 * (size_t)m->nv;
    double *sum = malloc(n3 * sizeof *sum);
    int *deg = malloc((size_t)m->nv * sizeof *deg);
    if (!sum || !deg) {
        free(sum);
        free(deg);
        return TCB_ERR_NOMEM;
    }
    for (int round = 0; round < RELAX_ROUNDS; round++) {
        memset(sum, 0, n3 * sizeof *sum);
        memset(deg, 0, (size_t)m->nv * sizeof *deg);
        /* Each undirected edge lies on two faces, so summing the two other
         * corners of every face weights all neighbours equally. */
        for (int f = 0; f < m->nf; f++)
            for (int i = 0; i < 3; i++) {
                int32_t v = m->f[3 * f + i];
                for (int j = 1; j < 3; j++) {
                    int32_t w = m->f[3 * f + (i + j) % 3];
                    for (int k = 0; k < 3; k++) sum[3 * (size_t)v + k] += m->v[3 * (size_t)w + k];
                }
                deg[v] += 2;
            }
        for (int v = 0; v < m->nv; v++) {
            float *p = m->v + 3 * (size_t)v;
            for (int k = 0; k < 3; k++)
                p[k] += RELAX_STEP * (float)(sum[3 * (size_t)v + k] / deg[v] - p[k]);
            project(b, p);
        }
    }
    free(sum);
    free(deg);
    return TCB_OK;
}

/* ---- connectivity ------------------------------------------------------- */

static int32_t find_root(int32_t *parent, int32_t v)
{
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
}

static int count_pieces(const mesh_buf *m, int *pieces)
{
    int32_t *parent = malloc((size_t)m->nv * sizeof *parent);
    if (!parent) return TCB_ERR_NOMEM;
    for (int v = 0; v < m->nv; v++) parent[v] = v;
    for (int f = 0; f < m->nf; f++)
        for (int i = 1; i < 3; i++)
            parent[find_root(parent, m->f[3 * f + i])] = find_root(parent, m->f[3 * f]);
    *pieces = 0;
    for (int v = 0; v < m->nv; v++) *pieces += find_root(parent, v) == v;
    free(parent);
    return TCB_OK;
}

int tcb_synth_mesh_build(const tcb_synth_body *b, float **verts, int *nv, int32_t **faces, int *nf,
                         tcb_error *err)
{
    lattice L;
    mesh_buf m;
    memset(&m, 0, sizeof m);
    int pieces = 0;
    int rc = lattice_init(&L, b);
    if (!rc) rc = hash_rehash(&m);
    if (!rc) rc = march_lattice(&m, &L);
    if (!rc) rc = relax(b, &m);
    if (!rc) rc = count_pieces(&m, &pieces);
    free(L.field);
    free(m.key);
    free(m.val);
    if (!rc && pieces != 1)
        rc = tcb_fail(err, TCB_ERR_INTERNAL, "synthetic body polygonized into %d pieces", pieces);
    else if (rc)
        rc = tcb_fail(err, TCB_ERR_NOMEM, "out of memory polygonizing a synthetic body");
    if (rc) {
        free(m.v);
        free(m.f);
        return rc;
    }
    *verts = m.v;
    *faces = m.f;
    *nv = m.nv;
    *nf = m.nf;
    return TCB_OK;
}
