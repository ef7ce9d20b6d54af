/* Geodesic error (tcb/geodesic.h): the edge graph, the searches against
 * Floyd–Warshall on small meshes (a grid, a closed bumpy blob, a bent tube,
 * and a mesh of several pieces with an isolated vertex), the landmark
 * bound, the unreachable rule, the normalisation by sqrt(area), the PCK
 * curve and AUC by hand, and the cell summary's pooling. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "metrics/geodesic_internal.h"
#include "tcb/geodesic.h"
#include "tcb/geometry.h"
#include "tcb/rng.h"
#include "bent_tube.h"
#include "testutil.h"

#define REL 1e-12

typedef struct mesh {
    int nv, nf;
    float *v;
    int32_t *f;
} mesh;

static void mesh_free(mesh *m) { free(m->v), free(m->f); }

static void check_close(double got, double want, double rel, const char *what, int at)
{
    if (!(fabs(got - want) <= rel * fmax(fabs(got), fabs(want))))
        fail_msg("%s [%d]: got %.17g, want %.17g", what, at, got, want);
}

/* ---- meshes ------------------------------------------------------------ */

/* nx × ny vertices spaced h in the xy plane, z jittered by up to `jitter`;
 * each cell split into two triangles along alternating diagonals. */
static mesh grid(int nx, int ny, float h, double jitter, uint64_t seed)
{
    mesh m = {nx * ny, 2 * (nx - 1) * (ny - 1), NULL, NULL};
    m.v = malloc((size_t)m.nv * 3 * sizeof *m.v);
    m.f = malloc((size_t)m.nf * 3 * sizeof *m.f);
    tcb_rng rng;
    tcb_rng_seed(&rng, seed);
    for (int y = 0; y < ny; y++)
        for (int x = 0; x < nx; x++) {
            float *p = m.v + 3 * (y * nx + x);
            p[0] = (float)x * h, p[1] = (float)y * h;
            p[2] = (float)(jitter * tcb_rng_uniform(&rng));
        }
    int32_t *t = m.f;
    for (int y = 0; y + 1 < ny; y++)
        for (int x = 0; x + 1 < nx; x++) {
            int32_t a = y * nx + x, b = a + 1, c = a + nx, d = c + 1;
            if ((x + y) % 2) *t++ = a, *t++ = b, *t++ = d, *t++ = a, *t++ = d, *t++ = c;
            else *t++ = a, *t++ = b, *t++ = c, *t++ = b, *t++ = d, *t++ = c;
        }
    return m;
}

/* A closed tube (bent_tube.h): bent by `bend` radians (a U at π), its
 * radius wobbling by `bump`. */
static mesh tube(int rings, int segs, double bend, double bump, uint64_t seed)
{
    mesh m = {bent_tube_verts(rings, segs), bent_tube_faces(rings, segs), NULL, NULL};
    m.v = malloc((size_t)m.nv * 3 * sizeof *m.v);
    m.f = malloc((size_t)m.nf * 3 * sizeof *m.f);
    bent_tube(rings, segs, 6.0, bend, bump, seed, m.v, m.f);
    return m;
}

/* Three pieces: a 5 × 4 grid (vertices 0-19), a tetrahedron (20-23) with a
 * degenerate face repeating a vertex, and vertex 24 on no face. */
static mesh pieces(void)
{
    mesh g = grid(5, 4, 0.25f, 0.1, 7);
    mesh m = {g.nv + 5, g.nf + 5, NULL, NULL};
    m.v = malloc((size_t)m.nv * 3 * sizeof *m.v);
    m.f = malloc((size_t)m.nf * 3 * sizeof *m.f);
    memcpy(m.v, g.v, (size_t)g.nv * 3 * sizeof *m.v);
    memcpy(m.f, g.f, (size_t)g.nf * 3 * sizeof *m.f);
    const float tet[] = {2, 0, 0, 3, 0, 0, 2, 1, 0, 2, 0, 1, 5, 5, 5};
    memcpy(m.v + 3 * g.nv, tet, sizeof tet);
    const int32_t tf[] = {20, 21, 22, 20, 22, 23, 20, 23, 21, 21, 23, 22, 21, 21, 23};
    memcpy(m.f + 3 * g.nf, tf, sizeof tf);
    mesh_free(&g);
    return m;
}

/* ---- the reference: Floyd–Warshall on the faces' sides ------------------- */

static double side(const float *v, int a, int b)
{
    double s = 0;
    for (int c = 0; c < 3; c++) s += ((double)v[3 * a + c] - v[3 * b + c]) * ((double)v[3 * a + c] - v[3 * b + c]);
    return sqrt(s);
}

/* [nv][nv] all-pairs distances, INFINITY between pieces. */
static double *floyd_warshall(const mesh *m)
{
    int n = m->nv;
    double *d = malloc((size_t)n * n * sizeof *d);
    for (int i = 0; i < n * n; i++) d[i] = INFINITY;
    for (int i = 0; i < n; i++) d[(size_t)i * n + i] = 0;
    for (int f = 0; f < m->nf; f++)
        for (int c = 0; c < 3; c++) {
            int a = m->f[3 * f + c], b = m->f[3 * f + (c + 1) % 3];
            if (a == b) continue;
            d[(size_t)a * n + b] = d[(size_t)b * n + a] = side(m->v, a, b);
        }
    for (int k = 0; k < n; k++)
        for (int i = 0; i < n; i++)
            for (int j = 0; j < n; j++)
                if (d[(size_t)i * n + k] + d[(size_t)k * n + j] < d[(size_t)i * n + j])
                    d[(size_t)i * n + j] = d[(size_t)i * n + k] + d[(size_t)k * n + j];
    return d;
}

static tcb_edge_graph graph_of(const mesh *m)
{
    tcb_edge_graph g;
    tcb_error err = {0};
    if (tcb_edge_graph_build(m->f, m->nf, m->nv, &g, &err)) fail_msg("%s", err.msg);
    return g;
}

static double *lengths_of(const tcb_edge_graph *g, const mesh *m)
{
    double *w = malloc(((size_t)2 * g->n_edges + 1) * sizeof *w);
    tcb_edge_graph_lengths(g, m->v, w);
    return w;
}

/* What d(pred[k], k) must be: Floyd–Warshall's, or the straight line
 * between pieces. */
static void check_to_pred(const mesh *m, const double *fw, const int32_t *pred, const char *what)
{
    tcb_edge_graph g = graph_of(m);
    double *w = lengths_of(&g, m), *dist = tu_dalloc((size_t)m->nv);
    int unreachable = -1, want_unreachable = 0;
    tcb_error err = {0};
    if (tcb_geodesic_to_pred(&g, w, m->v, pred, dist, &unreachable, &err)) fail_msg("%s", err.msg);
    for (int k = 0; k < m->nv; k++) {
        double want = fw[(size_t)pred[k] * m->nv + k];
        if (isinf(want)) want = side(m->v, pred[k], k), want_unreachable++;
        assert_true(isfinite(dist[k]));
        check_close(dist[k], want, REL, what, k);
    }
    assert_int_equal(unreachable, want_unreachable);
    free(w), free(dist);
    tcb_edge_graph_free(&g);
}

/* The predictions each mesh is queried with: every kind of group. */
static void check_all_preds(const mesh *m, const double *fw, uint64_t seed)
{
    int n = m->nv;
    int32_t *pred = malloc((size_t)n * sizeof *pred);
    tcb_rng rng;
    tcb_rng_seed(&rng, seed);
    for (int k = 0; k < n; k++) pred[k] = (int32_t)tcb_rng_below(&rng, (uint64_t)n);
    check_to_pred(m, fw, pred, "random");
    for (int k = 0; k < n; k++) pred[k] = (k + n / 2) % n;
    check_to_pred(m, fw, pred, "shifted");
    for (int k = 0; k < n; k++) pred[k] = k % 2 ? k : (int32_t)tcb_rng_below(&rng, (uint64_t)n);
    check_to_pred(m, fw, pred, "half exact");
    for (int k = 0; k < n; k++) pred[k] = (k / 3) * 3; /* groups of three */
    check_to_pred(m, fw, pred, "threes");
    for (int s = 0; s < n; s += n / 7 + 1) { /* one source for all: one Dijkstra */
        for (int k = 0; k < n; k++) pred[k] = s;
        check_to_pred(m, fw, pred, "one source");
    }
    free(pred);
}

static void check_mesh(const mesh *m, uint64_t seed)
{
    double *fw = floyd_warshall(m);
    tcb_edge_graph g = graph_of(m);
    double *w = lengths_of(&g, m), *field = tu_dalloc((size_t)m->nv);
    tcb_error err = {0};
    for (int s = 0; s < m->nv; s++) {
        assert_int_equal(tcb_geodesic_field(&g, w, s, field, &err), TCB_OK);
        for (int v = 0; v < m->nv; v++) {
            double want = fw[(size_t)s * m->nv + v];
            if (isinf(want)) assert_true(isinf(field[v]));
            else check_close(field[v], want, REL, "field", v);
        }
    }
    check_all_preds(m, fw, seed);
    free(w), free(field), free(fw);
    tcb_edge_graph_free(&g);
}

/* ---- tests --------------------------------------------------------------- */

/* 3 × 2 grid: 9 sides (4 along x, 3 along y, 2 diagonals), one piece;
 * the pieces mesh: the degenerate face adds nothing, three components
 * numbered by their lowest vertex, the isolated vertex with no neighbour. */
static void test_graph_build(void **state)
{
    (void)state;
    mesh m = grid(3, 2, 1.0f, 0.0, 1);
    tcb_edge_graph g = graph_of(&m);
    assert_int_equal(g.n_edges, 9);
    assert_int_equal(g.offsets[g.n_verts], 18);
    assert_int_equal(g.n_components, 1);
    for (int v = 0; v < g.n_verts; v++)
        for (int32_t e = g.offsets[v] + 1; e < g.offsets[v + 1]; e++) assert_true(g.adj[e - 1] < g.adj[e]);
    /* vertex 1 (x = 1, y = 0): 0 and 2 beside, 4 above, and the diagonals
     * 1-3 and 1-5 of both cells (they alternate) */
    assert_int_equal(g.offsets[2] - g.offsets[1], 5);
    tcb_edge_graph_free(&g);
    mesh_free(&m);

    m = pieces();
    g = graph_of(&m);
    assert_int_equal(g.n_components, 3);
    assert_int_equal(g.component[0], 0);
    assert_int_equal(g.component[19], 0);
    assert_int_equal(g.component[20], 1);
    assert_int_equal(g.component[23], 1);
    assert_int_equal(g.component[24], 2);
    assert_int_equal(g.offsets[25] - g.offsets[24], 0);
    assert_int_equal(g.offsets[21] - g.offsets[20], 3); /* the tetrahedron: 6 sides, degree 3 */
    tcb_edge_graph_free(&g);

    tcb_error err = {0};
    m.f[5] = 25;
    assert_int_equal(tcb_edge_graph_build(m.f, m.nf, m.nv, &g, &err), TCB_ERR_INPUT);
    assert_non_null(strstr(err.msg, "face 1"));
    mesh_free(&m);
}

static void test_grid_vs_floyd_warshall(void **state)
{
    (void)state;
    mesh m = grid(12, 9, 0.1f, 0.08, 11);
    check_mesh(&m, 1);
    mesh_free(&m);
}

static void test_blob_vs_floyd_warshall(void **state)
{
    (void)state;
    mesh m = tube(9, 12, 0.3, 0.6, 12); /* short, nearly straight, very bumpy: a closed blob */
    check_mesh(&m, 2);
    mesh_free(&m);
}

static void test_bent_tube_vs_floyd_warshall(void **state)
{
    (void)state;
    mesh m = tube(24, 10, M_PI, 0.1, 13);
    check_mesh(&m, 3);
    mesh_free(&m);
}

static void test_pieces_vs_floyd_warshall(void **state)
{
    (void)state;
    mesh m = pieces();
    check_mesh(&m, 4);
    mesh_free(&m);
}

/* The landmark table holds exact distances, and A* with the landmark bound
 * finds every distance Floyd–Warshall does, on the bent tube (where the
 * straight line is a poor guide) and across pieces. */
static void test_landmarks(void **state)
{
    (void)state;
    for (int which = 0; which < 2; which++) {
        mesh m = which ? pieces() : tube(24, 10, M_PI, 0.1, 14);
        double *fw = floyd_warshall(&m);
        tcb_edge_graph g = graph_of(&m);
        double *w = lengths_of(&g, &m), *lm, slack;
        tcb_geo_view gv = {&g, w, m.v, NULL, 0};
        assert_int_equal(tcb_geo_landmarks(&gv, &lm, &slack), 0);
        assert_true(slack > 0 && slack < 1e-6);
        gv.lm = lm, gv.lm_slack = slack;
        int n = m.nv, distinct = 0;
        for (int l = 0; l < TCB_GEO_LANDMARKS; l++) {
            int at = -1;
            for (int v = 0; v < n && at < 0; v++)
                if (lm[(size_t)v * TCB_GEO_LANDMARKS + l] == 0 && g.component[v] == 0) at = v;
            assert_true(at >= 0); /* a landmark: its own distance is 0 */
            distinct += l == 0 || lm[(size_t)at * TCB_GEO_LANDMARKS + l - 1] != 0;
            for (int v = 0; v < n; v++) {
                double want = fw[(size_t)at * n + v];
                check_close(lm[(size_t)v * TCB_GEO_LANDMARKS + l], isinf(want) ? 0 : want, REL, "landmark", v);
            }
        }
        assert_true(distinct > TCB_GEO_LANDMARKS / 2);
        tcb_geo_ws ws;
        assert_int_equal(tcb_geo_ws_init(&ws, n), 0);
        for (int s = 0; s < n; s++)
            for (int t = 0; t < n; t++) {
                if (isinf(fw[(size_t)s * n + t])) continue;
                tcb_geo_ws_next(&ws);
                ws.goal[t] = ws.cur;
                assert_int_equal(tcb_geo_search(&gv, &ws, s, 1, t), 0);
                check_close(ws.g[t], fw[(size_t)s * n + t], REL, "A* with landmarks", s * n + t);
            }
        tcb_geo_ws_free(&ws);
        free(lm), free(w), free(fw);
        tcb_edge_graph_free(&g);
        mesh_free(&m);
    }
}

/* A pair large and bad enough to build landmarks after the probe (random
 * predictions on a U-shaped tube of 1 442 vertices), against the full
 * Dijkstra field of each source; the same bits with one thread and two. */
static void test_large_pair_and_threads(void **state)
{
    (void)state;
    mesh m = tube(60, 24, M_PI, 0.1, 15);
    tcb_edge_graph g = graph_of(&m);
    int n = m.nv;
    double *w = lengths_of(&g, &m), *field = tu_dalloc((size_t)n);
    double *one = tu_dalloc((size_t)n), *two = tu_dalloc((size_t)n);
    int32_t *pred = malloc((size_t)n * sizeof *pred);
    tcb_rng rng;
    tcb_rng_seed(&rng, 16);
    for (int k = 0; k < n; k++) pred[k] = (int32_t)tcb_rng_below(&rng, (uint64_t)n);
    tcb_error err = {0};
    int prev = omp_get_max_threads();
    omp_set_num_threads(1);
    assert_int_equal(tcb_geodesic_to_pred(&g, w, m.v, pred, one, NULL, &err), TCB_OK);
    omp_set_num_threads(2);
    assert_int_equal(tcb_geodesic_to_pred(&g, w, m.v, pred, two, NULL, &err), TCB_OK);
    omp_set_num_threads(prev);
    assert_memory_equal(one, two, (size_t)n * sizeof *one);
    for (int k = 0; k < n; k++) {
        assert_int_equal(tcb_geodesic_field(&g, w, pred[k], field, &err), TCB_OK);
        check_close(one[k], field[k], REL, "large pair", k);
    }
    free(w), free(field), free(one), free(two), free(pred);
    tcb_edge_graph_free(&g);
    mesh_free(&m);
}

/* The unreachable rule on the pieces: grid vertices predicted on the
 * tetrahedron and on the isolated vertex, and the reverse, score the
 * straight line and are counted; the isolated vertex predicted as itself
 * is exact (0, not counted). Never inf or NaN. */
static void test_unreachable_rule(void **state)
{
    (void)state;
    mesh m = pieces();
    tcb_edge_graph g = graph_of(&m);
    double *w = lengths_of(&g, &m), dist[25];
    int32_t pred[25];
    for (int k = 0; k < 25; k++) pred[k] = k;
    pred[0] = 24, pred[1] = 21, pred[24] = 3, pred[22] = 23, pred[5] = 6;
    int unreachable = 0;
    tcb_error err = {0};
    assert_int_equal(tcb_geodesic_to_pred(&g, w, m.v, pred, dist, &unreachable, &err), TCB_OK);
    assert_int_equal(unreachable, 3);
    check_close(dist[0], side(m.v, 24, 0), REL, "grid to isolated", 0);
    check_close(dist[1], side(m.v, 21, 1), REL, "grid to tetrahedron", 1);
    check_close(dist[24], side(m.v, 3, 24), REL, "isolated to grid", 24);
    check_close(dist[22], side(m.v, 23, 22), REL, "tetrahedron side", 22);
    check_close(dist[5], side(m.v, 6, 5), REL, "grid side", 5);
    for (int k = 0; k < 25; k++) assert_true(isfinite(dist[k]));
    assert_true(dist[2] == 0 && dist[20] == 0);

    tcb_pair_metrics pm = {0};
    double area = tcb_mesh_area(m.v, m.f, m.nf);
    assert_int_equal(tcb_pair_geodesic_compute(&g, m.v, area, pred, &pm, NULL, &err), TCB_OK);
    assert_int_equal(pm.geo_unreachable, 3);
    assert_true(isfinite(pm.geo.mean) && isfinite(pm.geo.m2) && isfinite(pm.geo_auc));
    free(w);
    tcb_edge_graph_free(&g);
    mesh_free(&m);
}

/* e_k = d(pred[k], k) / sqrt(area): against Floyd–Warshall; and a mesh
 * scaled by 4 (exact in binary) gives the very same bits. */
static void test_normalisation(void **state)
{
    (void)state;
    mesh m = tube(9, 12, 1.0, 0.4, 17);
    int n = m.nv;
    double *fw = floyd_warshall(&m);
    tcb_edge_graph g = graph_of(&m);
    int32_t *pred = malloc((size_t)n * sizeof *pred);
    tcb_rng rng;
    tcb_rng_seed(&rng, 18);
    for (int k = 0; k < n; k++) pred[k] = (int32_t)tcb_rng_below(&rng, (uint64_t)n);
    double *e = tu_dalloc((size_t)n), *e4 = tu_dalloc((size_t)n), sum = 0;
    double area = tcb_mesh_area(m.v, m.f, m.nf);
    tcb_pair_metrics pm = {0}, pm4 = {0};
    tcb_error err = {0};
    assert_int_equal(tcb_pair_geodesic_compute(&g, m.v, area, pred, &pm, e, &err), TCB_OK);
    for (int k = 0; k < n; k++) {
        double want = fw[(size_t)pred[k] * n + k] / sqrt(area);
        check_close(e[k], want, REL, "normalised", k);
        sum += want;
    }
    assert_true(pm.geo.n == n);
    check_close(pm.geo.mean, sum / n, REL, "m_geo", 0);
    for (int i = 0; i < 3 * n; i++) m.v[i] *= 4.0f;
    assert_int_equal(tcb_pair_geodesic_compute(&g, m.v, tcb_mesh_area(m.v, m.f, m.nf), pred, &pm4, e4, &err),
                     TCB_OK);
    assert_memory_equal(e, e4, (size_t)n * sizeof *e);
    assert_true(pm.geo.mean == pm4.geo.mean && pm.geo_auc == pm4.geo_auc);
    free(fw), free(pred), free(e), free(e4);
    tcb_edge_graph_free(&g);
    mesh_free(&m);
}

/* The geodesic PCK by hand. An 11 × 11 flat grid of spacing 1/8 (exact):
 * area 1.5625, sqrt 1.25, so one step along x is e = 0.1 and two are 0.2.
 * Thresholds t_s = s·0.25/99: 0.1 passes from s = 40 (39·0.25/99 < 0.1 <
 * 40·0.25/99), 0.2 from s = 80. Of the 121 vertices, 11 (the first column)
 * go two steps right, 22 (second and third columns) one step, the rest are
 * exact: PCK = 88/121 below s = 40, 110/121 below 80, 1 from 80, and
 * AUC = (40·88 + 40·110 + 20·121) / (100·121). */
static void test_pck_by_hand(void **state)
{
    (void)state;
    mesh m = grid(11, 11, 0.125f, 0.0, 19);
    tcb_edge_graph g = graph_of(&m);
    int32_t pred[121];
    for (int k = 0; k < 121; k++) pred[k] = k % 11 == 0 ? k + 2 : k % 11 <= 2 ? k + 1 : k;
    double area = tcb_mesh_area(m.v, m.f, m.nf);
    assert_true(area == 1.5625);
    tcb_pair_metrics pm = {0};
    tcb_error err = {0};
    assert_int_equal(tcb_pair_geodesic_compute(&g, m.v, area, pred, &pm, NULL, &err), TCB_OK);
    for (int s = 0; s < TCB_GEO_PCK_STEPS; s++) {
        double want = s < 40 ? 88.0 / 121 : s < 80 ? 110.0 / 121 : 1.0;
        if (fabs(pm.geo_pck[s] - want) > 1e-15) fail_msg("geo_pck[%d] = %.17g, want %.17g", s, pm.geo_pck[s], want);
    }
    check_close(pm.geo_auc, (40.0 * 88 + 40.0 * 110 + 20.0 * 121) / (100.0 * 121), REL, "AUC", 0);
    check_close(pm.geo.mean, (11 * 0.2 + 22 * 0.1) / 121, REL, "m_geo", 0);
    assert_int_equal(pm.geo_unreachable, 0);
    assert_true(tcb_geo_pck_threshold(0) == 0 && tcb_geo_pck_threshold(99) == 0.25);
    check_close(tcb_geo_pck_threshold(40), 40 * (0.25 / 99), 1e-15, "t_40", 40);
    tcb_edge_graph_free(&g);
    mesh_free(&m);
}

/* Cell summaries pool m_geo over every vertex of the pairs that have it and
 * average the curve over those pairs only: a pair scored before the
 * geodesic error existed (geo.n = 0) leaves it alone. */
static void test_summary(void **state)
{
    (void)state;
    tcb_pair_metrics a = {0}, b = {0}, old = {0};
    for (int k = 0; k < 4; k++) tcb_stat_push(&a.geo, 0.1 * k), tcb_stat_push(&b.geo, 0.5);
    a.geo_auc = 0.8, b.geo_auc = 0.4, a.geo_unreachable = 2, b.geo_unreachable = 1;
    for (int s = 0; s < TCB_GEO_PCK_STEPS; s++) a.geo_pck[s] = 1.0, b.geo_pck[s] = 0.0;
    old.auc = 0.5;
    tcb_summary s, t;
    tcb_summary_init(&s);
    tcb_summary_add_pair(&s, &a, NAN);
    tcb_summary_add_pair(&s, &old, NAN);
    tcb_summary_add_pair(&s, &b, NAN);
    assert_int_equal(s.n_pairs, 3);
    assert_true(s.geo.n == 8 && s.geo_auc.n == 2 && s.geo_unreachable == 3);
    check_close(s.geo.mean, (0.6 + 2.0) / 8, REL, "pooled m_geo", 0);
    check_close(s.geo_auc.mean, 0.6, REL, "AUC over pairs", 0);
    check_close(s.geo_pck[7], 0.5, REL, "curve over pairs", 7);
    tcb_summary_init(&t);
    tcb_summary_add_pair(&t, &old, NAN);
    tcb_summary_merge(&t, &s);
    check_close(t.geo_pck[7], 0.5, REL, "merged into an old summary", 7);
    assert_true(t.geo_auc.n == 2 && t.n_pairs == 4);
}

static void test_errors(void **state)
{
    (void)state;
    mesh m = grid(3, 3, 1.0f, 0.0, 20);
    tcb_edge_graph g = graph_of(&m);
    double *w = lengths_of(&g, &m), d[9];
    int32_t pred[9] = {0, 1, 2, 3, 4, 5, 6, 7, 9};
    tcb_pair_metrics pm = {0};
    tcb_error err = {0};
    assert_int_equal(tcb_geodesic_to_pred(&g, w, m.v, pred, d, NULL, &err), TCB_ERR_INPUT);
    assert_non_null(strstr(err.msg, "pred[8]"));
    pred[8] = 8;
    assert_int_equal(tcb_pair_geodesic_compute(&g, m.v, 0.0, pred, &pm, NULL, &err), TCB_ERR_INPUT);
    assert_int_equal(tcb_pair_geodesic_compute(&g, m.v, NAN, pred, &pm, NULL, &err), TCB_ERR_INPUT);
    assert_int_equal(tcb_geodesic_field(&g, w, 9, d, &err), TCB_ERR_INPUT);
    tcb_edge_graph none;
    assert_int_equal(tcb_edge_graph_build(m.f, m.nf, 0, &none, &err), TCB_ERR_INPUT);
    free(w);
    tcb_edge_graph_free(&g);
    mesh_free(&m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_graph_build),
        cmocka_unit_test(test_grid_vs_floyd_warshall),
        cmocka_unit_test(test_blob_vs_floyd_warshall),
        cmocka_unit_test(test_bent_tube_vs_floyd_warshall),
        cmocka_unit_test(test_pieces_vs_floyd_warshall),
        cmocka_unit_test(test_landmarks),
        cmocka_unit_test(test_large_pair_and_threads),
        cmocka_unit_test(test_unreachable_rule),
        cmocka_unit_test(test_normalisation),
        cmocka_unit_test(test_pck_by_hand),
        cmocka_unit_test(test_summary),
        cmocka_unit_test(test_errors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
