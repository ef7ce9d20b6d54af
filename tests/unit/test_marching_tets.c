/* neural/marching_tets.c: a sphere's SDF on a cube lattice cut into
 * positively oriented tets gives a closed, consistently wound surface whose
 * normals point toward s > 0 and whose vertices lie on the sphere; the
 * vertex order is the crossing edges' lexicographic order; the backward
 * pass matches central differences of the vertex positions in s and x;
 * every one of the 16 occupancy codes gives kaolin's triangle count; bad
 * tets are refused. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "neural/marching_tets.h"
#include "tcb/rng.h"

typedef struct grid {
    int nv, nt;
    float *x;
    int32_t *tets;
} grid;

static double orient(const float *x, const int32_t *t)
{
    const float *a = x + 3 * t[0], *b = x + 3 * t[1], *c = x + 3 * t[2], *d = x + 3 * t[3];
    double u[3], w[3], z[3];
    for (int k = 0; k < 3; k++) u[k] = b[k] - a[k], w[k] = c[k] - a[k], z[k] = d[k] - a[k];
    return u[0] * (w[1] * z[2] - w[2] * z[1]) - u[1] * (w[0] * z[2] - w[2] * z[0]) + u[2] * (w[0] * z[1] - w[1] * z[0]);
}

/* An n³ lattice of cubes over [-1, 1]³, each cut into the six Kuhn tets
 * along its main diagonal (a conforming mesh), each turned positive. */
static grid lattice(int n)
{
    grid g = {(n + 1) * (n + 1) * (n + 1), 6 * n * n * n, NULL, NULL};
    g.x = malloc((size_t)g.nv * 3 * sizeof *g.x);
    g.tets = malloc((size_t)g.nt * 4 * sizeof *g.tets);
    for (int i = 0; i <= n; i++)
        for (int j = 0; j <= n; j++)
            for (int k = 0; k <= n; k++) {
                float *p = g.x + 3 * ((i * (n + 1) + j) * (n + 1) + k);
                p[0] = -1.0f + 2.0f * i / n, p[1] = -1.0f + 2.0f * j / n, p[2] = -1.0f + 2.0f * k / n;
            }
    /* Kuhn: the paths 0 → 7 through the cube's corners, one per axis order. */
    static const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
    int t = 0;
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++)
            for (int k = 0; k < n; k++)
                for (int p = 0; p < 6; p++) {
                    int c[3] = {i, j, k};
                    int32_t *q = g.tets + 4 * t++;
                    q[0] = (c[0] * (n + 1) + c[1]) * (n + 1) + c[2];
                    for (int s = 0; s < 3; s++) {
                        c[perms[p][s]]++;
                        q[s + 1] = (c[0] * (n + 1) + c[1]) * (n + 1) + c[2];
                    }
                    if (orient(g.x, q) < 0) {
                        int32_t y = q[2];
                        q[2] = q[3], q[3] = y;
                    }
                }
    return g;
}

static void grid_free(grid *g) { free(g->x), free(g->tets); }

/* A sphere of radius r about c, positive outside. */
static float *sphere_sdf(const grid *g, const double c[3], double r)
{
    float *s = malloc((size_t)g->nv * sizeof *s);
    for (int i = 0; i < g->nv; i++) {
        double d2 = 0;
        for (int k = 0; k < 3; k++) d2 += (g->x[3 * i + k] - c[k]) * (g->x[3 * i + k] - c[k]);
        s[i] = (float)(sqrt(d2) - r);
    }
    return s;
}

static int cmp_edge(const void *a, const void *b)
{
    const int64_t *x = a, *y = b;
    return (*x > *y) - (*x < *y);
}

static void test_sphere_closed_and_outward(void **state)
{
    (void)state;
    grid g = lattice(12);
    const double c[3] = {0.05, -0.03, 0.02}, r = 0.7;
    float *s = sphere_sdf(&g, c, r);
    tcb_mt_surface m;
    tcb_error err = {0};
    assert_int_equal(tcb_marching_tets_forward(g.x, s, g.nv, g.tets, g.nt, &m, &err), TCB_OK);
    assert_true(m.n_faces > 500 && m.n_verts > 250);
    /* Vertex order: the crossing edges, sorted, each once, one end occupied. */
    for (int i = 0; i < m.n_verts; i++) {
        int32_t a = m.edges[2 * i], b = m.edges[2 * i + 1];
        assert_true(a < b);
        assert_true((s[a] > 0) != (s[b] > 0));
        if (i) {
            int32_t pa = m.edges[2 * i - 2], pb = m.edges[2 * i - 1];
            assert_true(pa < a || (pa == a && pb < b));
        }
    }
    /* Closed and consistently wound: every directed edge once, and its
     * reverse once. Vertices on the sphere to the lattice's resolution,
     * normals toward the outside (s > 0). */
    int64_t *dir = malloc((size_t)m.n_faces * 3 * sizeof *dir), *rev = malloc((size_t)m.n_faces * 3 * sizeof *rev);
    for (int f = 0; f < m.n_faces; f++) {
        const int32_t *t = m.faces + 3 * f;
        const float *p0 = m.verts + 3 * t[0], *p1 = m.verts + 3 * t[1], *p2 = m.verts + 3 * t[2];
        double u[3], w[3], cen[3];
        for (int k = 0; k < 3; k++) u[k] = p1[k] - p0[k], w[k] = p2[k] - p0[k], cen[k] = (p0[k] + p1[k] + p2[k]) / 3 - c[k];
        double nrm[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
        assert_true(nrm[0] * cen[0] + nrm[1] * cen[1] + nrm[2] * cen[2] > 0);
        for (int e = 0; e < 3; e++) {
            int64_t a = t[e], b = t[(e + 1) % 3];
            assert_true(a != b);
            dir[3 * f + e] = a * m.n_verts + b;
            rev[3 * f + e] = b * m.n_verts + a;
        }
    }
    qsort(dir, (size_t)m.n_faces * 3, sizeof *dir, cmp_edge);
    qsort(rev, (size_t)m.n_faces * 3, sizeof *rev, cmp_edge);
    for (int e = 0; e < 3 * m.n_faces; e++) {
        assert_true(e == 0 || dir[e] != dir[e - 1]);
        assert_true(dir[e] == rev[e]);
    }
    /* Euler characteristic 2: one sphere. */
    assert_int_equal(m.n_verts - 3 * m.n_faces / 2 + m.n_faces, 2);
    double h = 2.0 / 12;
    for (int i = 0; i < m.n_verts; i++) {
        double d2 = 0;
        for (int k = 0; k < 3; k++) d2 += (m.verts[3 * i + k] - c[k]) * (m.verts[3 * i + k] - c[k]);
        assert_true(fabs(sqrt(d2) - r) < 0.1 * h);
    }
    free(dir), free(rev), free(s);
    tcb_mt_surface_free(&m);
    grid_free(&g);
}

/* Σ w · v for fixed weights w: its gradient is backward(w). */
static double weighted_sum(const grid *g, const float *s, const float *w, int n_expect)
{
    tcb_mt_surface m;
    tcb_error err = {0};
    assert_int_equal(tcb_marching_tets_forward(g->x, s, g->nv, g->tets, g->nt, &m, &err), TCB_OK);
    assert_int_equal(m.n_verts, n_expect);
    double acc = 0;
    for (int i = 0; i < 3 * m.n_verts; i++) acc += (double)w[i] * m.verts[i];
    tcb_mt_surface_free(&m);
    return acc;
}

static void test_gradient_finite_differences(void **state)
{
    (void)state;
    grid g = lattice(4);
    tcb_rng rng;
    tcb_rng_seed(&rng, 7);
    float *s = malloc((size_t)g.nv * sizeof *s);
    const double c[3] = {0.1, 0.0, -0.1};
    float *base = sphere_sdf(&g, c, 0.6);
    /* Values kept ≥ 0.05 from zero so that a step of 1e-3 changes no sign. */
    for (int i = 0; i < g.nv; i++) {
        float v = base[i] + 0.05f * (float)(tcb_rng_uniform(&rng) - 0.5);
        s[i] = fabsf(v) < 0.05f ? (v < 0 ? -0.05f : 0.05f) : v;
    }
    tcb_mt_surface m;
    tcb_error err = {0};
    assert_int_equal(tcb_marching_tets_forward(g.x, s, g.nv, g.tets, g.nt, &m, &err), TCB_OK);
    float *w = malloc((size_t)m.n_verts * 3 * sizeof *w);
    for (int i = 0; i < 3 * m.n_verts; i++) w[i] = (float)(2 * tcb_rng_uniform(&rng) - 1);
    float *dx = calloc((size_t)g.nv * 3, sizeof *dx), *ds = calloc((size_t)g.nv, sizeof *ds);
    tcb_marching_tets_backward(g.x, s, &m, w, dx, ds);
    const float eps = 1e-3f;
    int checked = 0;
    for (int i = 0; i < g.nv; i++) {
        float keep = s[i];
        s[i] = keep + eps;
        double up = weighted_sum(&g, s, w, m.n_verts);
        s[i] = keep - eps;
        double down = weighted_sum(&g, s, w, m.n_verts);
        s[i] = keep;
        double fd = (up - down) / (2 * eps);
        assert_true(fabs(fd - ds[i]) <= 2e-3 * (1 + fabs(fd)));
        checked += ds[i] != 0;
        for (int k = 0; k < 3; k++) {
            float xk = g.x[3 * i + k];
            g.x[3 * i + k] = xk + eps;
            up = weighted_sum(&g, s, w, m.n_verts);
            g.x[3 * i + k] = xk - eps;
            down = weighted_sum(&g, s, w, m.n_verts);
            g.x[3 * i + k] = xk;
            fd = (up - down) / (2 * eps);
            assert_true(fabs(fd - dx[3 * i + k]) <= 2e-3 * (1 + fabs(fd)));
        }
    }
    assert_true(checked > 20); /* the surface touches many grid vertices */
    free(w), free(dx), free(ds), free(s), free(base);
    tcb_mt_surface_free(&m);
    grid_free(&g);
}

/* One positively oriented tet in each of the 16 occupancy codes: kaolin's
 * triangle counts, every face's normal toward the occupied corners. */
static void test_every_case(void **state)
{
    (void)state;
    const float x[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    const int32_t tet[4] = {0, 1, 2, 3};
    const int expect[16] = {0, 1, 1, 2, 1, 2, 2, 1, 1, 2, 2, 1, 2, 1, 1, 0};
    for (int code = 0; code < 16; code++) {
        float s[4];
        double occ[3] = {0, 0, 0};
        int n_occ = 0;
        for (int k = 0; k < 4; k++) {
            s[k] = code >> k & 1 ? 0.5f + 0.1f * k : -0.4f - 0.1f * k;
            if (s[k] > 0) {
                for (int d = 0; d < 3; d++) occ[d] += x[3 * k + d];
                n_occ++;
            }
        }
        tcb_mt_surface m;
        tcb_error err = {0};
        assert_int_equal(tcb_marching_tets_forward(x, s, 4, tet, 1, &m, &err), TCB_OK);
        assert_int_equal(m.n_faces, expect[code]);
        assert_int_equal(m.n_verts, n_occ * (4 - n_occ));
        for (int f = 0; f < m.n_faces; f++) {
            const float *p0 = m.verts + 3 * m.faces[3 * f], *p1 = m.verts + 3 * m.faces[3 * f + 1],
                        *p2 = m.verts + 3 * m.faces[3 * f + 2];
            double u[3], w[3], to[3];
            for (int d = 0; d < 3; d++) u[d] = p1[d] - p0[d], w[d] = p2[d] - p0[d], to[d] = occ[d] / n_occ - p0[d];
            double nrm[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
            assert_true(nrm[0] * to[0] + nrm[1] * to[1] + nrm[2] * to[2] > 0);
        }
        tcb_mt_surface_free(&m);
    }
}

static void test_bad_tets(void **state)
{
    (void)state;
    const float x[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1}, s[4] = {1, -1, -1, -1};
    const int32_t tet[4] = {0, 1, 2, 4};
    tcb_mt_surface m;
    tcb_error err = {0};
    assert_int_equal(tcb_marching_tets_forward(x, s, 4, tet, 1, &m, &err), TCB_ERR_INPUT);
    assert_non_null(strstr(err.msg, "tet 0 names vertex 4 of 4"));
    assert_int_equal(m.n_verts, 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sphere_closed_and_outward),
        cmocka_unit_test(test_gradient_finite_differences),
        cmocka_unit_test(test_every_case),
        cmocka_unit_test(test_bad_tets),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
