/* The pieces of DynoSurf's grid: the convex hull (every point inside every
 * face's plane, closed, wound outward), the offset hull (every vertex at
 * the offset from the hull, to the ball's polytope), and TetGen's filling
 * (volumes adding up to the shell's, each within the bound and positive,
 * the shell's vertices first, the boundary the shell's area), with its
 * errors: no program, a shell TetGen cannot fill, bad parameters. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tcb/geometry.h"
#include "tcb/locate.h"
#include "tcb/meshing.h"
#include "tcb/rng.h"
#include "tcb/tetmesh.h"

static int cmp_i64(const void *a, const void *b)
{
    const int64_t *x = a, *y = b;
    return (*x > *y) - (*x < *y);
}

/* Closed and consistently wound: every directed edge once, its reverse once. */
static void assert_closed(const tcb_mesh *m)
{
    size_t ne = (size_t)m->n_faces * 3;
    int64_t *dir = malloc(ne * sizeof *dir), *rev = malloc(ne * sizeof *rev);
    for (int f = 0; f < m->n_faces; f++)
        for (int e = 0; e < 3; e++) {
            int64_t a = m->faces[3 * f + e], b = m->faces[3 * f + (e + 1) % 3];
            dir[3 * f + e] = a * m->n_verts + b, rev[3 * f + e] = b * m->n_verts + a;
        }
    qsort(dir, ne, sizeof *dir, cmp_i64);
    qsort(rev, ne, sizeof *rev, cmp_i64);
    for (size_t e = 0; e < ne; e++) {
        assert_true(e == 0 || dir[e] != dir[e - 1]);
        assert_true(dir[e] == rev[e]);
    }
    free(dir), free(rev);
}

/* Signed volume of a closed mesh (positive when wound outward). */
static double volume(const tcb_mesh *m)
{
    double v = 0;
    for (int f = 0; f < m->n_faces; f++) {
        const float *a = m->verts + 3 * m->faces[3 * f], *b = m->verts + 3 * m->faces[3 * f + 1],
                    *c = m->verts + 3 * m->faces[3 * f + 2];
        v += (a[0] * ((double)b[1] * c[2] - (double)b[2] * c[1]) - a[1] * ((double)b[0] * c[2] - (double)b[2] * c[0]) +
              a[2] * ((double)b[0] * c[1] - (double)b[1] * c[0])) / 6;
    }
    return v;
}

/* n points in an ellipsoid's volume, seeded. */
static float *ellipsoid_points(int n, uint64_t seed)
{
    tcb_rng rng;
    tcb_rng_seed(&rng, seed);
    float *p = malloc((size_t)n * 3 * sizeof *p);
    for (int i = 0; i < n;) {
        double x = 2 * tcb_rng_uniform(&rng) - 1, y = 2 * tcb_rng_uniform(&rng) - 1, z = 2 * tcb_rng_uniform(&rng) - 1;
        if (x * x + y * y + z * z > 1) continue;
        p[3 * i] = (float)(0.5 * x), p[3 * i + 1] = (float)(0.3 * y), p[3 * i + 2] = (float)(0.2 * z);
        i++;
    }
    return p;
}

static void test_convex_hull(void **state)
{
    (void)state;
    const int n = 2000;
    float *p = ellipsoid_points(n, 3);
    tcb_mesh hull;
    tcb_error err = {0};
    assert_int_equal(tcb_convex_hull(p, n, &hull, &err), TCB_OK);
    assert_true(hull.n_verts >= 4 && hull.n_verts < n);
    assert_closed(&hull);
    assert_true(volume(&hull) > 0);
    /* Every point on the inner side of every face's plane. */
    for (int f = 0; f < hull.n_faces; f++) {
        const float *a = hull.verts + 3 * hull.faces[3 * f], *b = hull.verts + 3 * hull.faces[3 * f + 1],
                    *c = hull.verts + 3 * hull.faces[3 * f + 2];
        double u[3], w[3];
        for (int k = 0; k < 3; k++) u[k] = b[k] - a[k], w[k] = c[k] - a[k];
        double nrm[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
        double len = sqrt(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]);
        for (int i = 0; i < n; i++) {
            double d = 0;
            for (int k = 0; k < 3; k++) d += nrm[k] * (p[3 * i + k] - a[k]);
            assert_true(d / len < 1e-6);
        }
    }
    tcb_mesh_free(&hull);
    free(p);
}

static void test_convex_offset(void **state)
{
    (void)state;
    const int n = 500;
    const double r = 0.1;
    float *p = ellipsoid_points(n, 5);
    tcb_mesh hull, shell;
    tcb_error err = {0};
    assert_int_equal(tcb_convex_hull(p, n, &hull, &err), TCB_OK);
    assert_int_equal(tcb_convex_offset(p, n, r, &shell, &err), TCB_OK);
    assert_closed(&shell);
    /* Every shell vertex a hull vertex moved by the offset along one of
     * the directions: at most the offset from the hull, and at least
     * offset·cos of the directions' spacing (1.5 % less measured here). */
    tcb_surface_point *loc = malloc((size_t)shell.n_verts * sizeof *loc);
    float *d2 = malloc((size_t)shell.n_verts * sizeof *d2);
    assert_int_equal(tcb_mesh_locate(hull.verts, hull.n_verts, hull.faces, hull.n_faces, shell.verts, shell.n_verts,
                                     loc, d2, &err),
                     TCB_OK);
    for (int i = 0; i < shell.n_verts; i++) assert_true(sqrt(d2[i]) > 0.98 * r && sqrt(d2[i]) < r * (1 + 1e-5));
    free(loc), free(d2);
    double hull_volume = volume(&hull), shell_volume = volume(&shell);
    assert_true(shell_volume > hull_volume);
    tcb_mesh_free(&hull);
    tcb_mesh_free(&shell);
    assert_int_equal(tcb_convex_offset(p, n, 0.0, &shell, &err), TCB_ERR_INPUT);
    free(p);
}

/* The unit cube [0, 1]³ as 12 outward triangles. */
static tcb_mesh cube(int drop_face)
{
    static const float v[24] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1};
    static const int32_t f[36] = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
                                  1, 2, 6, 1, 6, 5, 2, 3, 7, 2, 7, 6, 3, 0, 4, 3, 4, 7};
    tcb_mesh m = {8, drop_face ? 11 : 12, malloc(sizeof v), malloc(sizeof f)};
    memcpy(m.verts, v, sizeof v);
    memcpy(m.faces, f, sizeof f);
    if (drop_face) memmove(m.faces + 3 * 10, m.faces + 3 * 11, 3 * sizeof *m.faces);
    return m;
}

static double tet_volume(const tcb_tetmesh *t, int k)
{
    const int32_t *q = t->tets + 4 * k;
    const float *a = t->verts + 3 * q[0], *b = t->verts + 3 * q[1], *c = t->verts + 3 * q[2], *d = t->verts + 3 * q[3];
    double u[3], w[3], z[3];
    for (int x = 0; x < 3; x++) u[x] = b[x] - a[x], w[x] = c[x] - a[x], z[x] = d[x] - a[x];
    return (u[0] * (w[1] * z[2] - w[2] * z[1]) - u[1] * (w[0] * z[2] - w[2] * z[0]) + u[2] * (w[0] * z[1] - w[1] * z[0])) / 6;
}

/* The box's signed distance in closed form: outside, the length of the
 * excess over the box; inside, minus the distance to the nearest face. */
static double unit_box_signed_distance(const float *q)
{
    double out2 = 0, in = 1;
    for (int d = 0; d < 3; d++) {
        double e = fmax(fmax(q[d] - 1.0, -(double)q[d]), 0.0);
        out2 += e * e;
        in = fmin(in, fmin(q[d], 1.0 - q[d]));
    }
    return out2 > 0 ? sqrt(out2) : -in;
}

static void test_convex_signed_distance(void **state)
{
    (void)state;
    tcb_mesh box = cube(0);
    const int n = 4000;
    float *q = malloc((size_t)n * 3 * sizeof *q), *sd = malloc((size_t)n * sizeof *sd);
    tcb_rng rng;
    tcb_rng_seed(&rng, 11);
    for (int i = 0; i < 3 * n; i++) q[i] = (float)(2 * tcb_rng_uniform(&rng) - 0.5);
    tcb_error err = {0};
    assert_int_equal(tcb_convex_signed_distance(&box, q, n, sd, &err), TCB_OK);
    int inside = 0;
    for (int i = 0; i < n; i++) {
        assert_float_equal(sd[i], unit_box_signed_distance(q + 3 * i), 1e-6);
        inside += sd[i] < 0;
    }
    assert_true(inside > n / 16 && inside < n / 4); /* 1/8 of the volume */
    q[7] = NAN;
    assert_int_equal(tcb_convex_signed_distance(&box, q, n, sd, &err), TCB_ERR_NUMERIC);
    free(q), free(sd);
    tcb_mesh_free(&box);
}

static void test_tetrahedralize_cube(void **state)
{
    (void)state;
    tcb_mesh shell = cube(0);
    tcb_tetmesh t;
    tcb_error err = {0};
    const double max_volume = 0.002;
    assert_int_equal(tcb_tetrahedralize(&shell, max_volume, 2.0, &t, &err), TCB_OK);
    assert_true(t.n_tets >= 500 && t.n_verts > 8);
    assert_memory_equal(t.verts, shell.verts, 24 * sizeof(float));
    double total = 0;
    for (int k = 0; k < t.n_tets; k++) {
        double v = tet_volume(&t, k);
        assert_true(v > 0 && v <= max_volume * (1 + 1e-5));
        total += v;
    }
    assert_true(fabs(total - 1.0) < 1e-5);
    /* The boundary (faces of one tet only) covers the cube's area 6. */
    int64_t *keys = malloc((size_t)t.n_tets * 4 * 3 * sizeof *keys);
    static const int opp[4][3] = {{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}};
    size_t nk = 0;
    for (int k = 0; k < t.n_tets; k++)
        for (int f = 0; f < 4; f++) {
            int32_t c[3] = {t.tets[4 * k + opp[f][0]], t.tets[4 * k + opp[f][1]], t.tets[4 * k + opp[f][2]]};
            for (int a = 0; a < 2; a++) /* sort the three ids */
                for (int b = 0; b < 2 - a; b++)
                    if (c[b] > c[b + 1]) { int32_t x = c[b]; c[b] = c[b + 1], c[b + 1] = x; }
            keys[nk++] = ((int64_t)c[0] * t.n_verts + c[1]) * t.n_verts + c[2];
        }
    qsort(keys, nk, sizeof *keys, cmp_i64);
    double area = 0;
    for (size_t i = 0; i < nk;) {
        size_t j = i;
        while (j < nk && keys[j] == keys[i]) j++;
        assert_true(j - i <= 2);
        if (j - i == 1) {
            int64_t k = keys[i];
            int32_t c = (int32_t)(k % t.n_verts), b = (int32_t)(k / t.n_verts % t.n_verts),
                    a = (int32_t)(k / t.n_verts / t.n_verts);
            area += tcb_triangle_area(t.verts + 3 * a, t.verts + 3 * b, t.verts + 3 * c);
        }
        i = j;
    }
    assert_true(fabs(area - 6.0) < 1e-4);
    free(keys);
    tcb_tetmesh_free(&t);
    tcb_mesh_free(&shell);
}

static void test_tetrahedralize_errors(void **state)
{
    (void)state;
    tcb_mesh shell = cube(0), open_box = cube(1);
    tcb_tetmesh t;
    tcb_error err = {0};
    assert_int_equal(tcb_tetrahedralize(&shell, 0.0, 2.0, &t, &err), TCB_ERR_INPUT);
    assert_non_null(strstr(err.msg, "maximum volume of 0"));
    assert_int_equal(tcb_tetrahedralize(&shell, 0.01, 1.0, &t, &err), TCB_ERR_INPUT);
    assert_non_null(strstr(err.msg, "radius-edge bound of 1"));
    /* TetGen stops on an open shell: one line naming it, nothing left. */
    assert_int_equal(tcb_tetrahedralize(&open_box, 0.01, 2.0, &t, &err), TCB_ERR_NUMERIC);
    assert_non_null(strstr(err.msg, "tetgen -p"));
    assert_null(strchr(err.msg, '\n'));
    assert_int_equal(t.n_tets, 0);
    /* A shell with a face twice: TetGen aborts, without a word of why. */
    static const float tv[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    static const int32_t tf[15] = {0, 2, 1, 0, 1, 3, 1, 2, 3, 0, 3, 2, 0, 1, 2};
    tcb_mesh twice = {4, 5, (float *)tv, (int32_t *)tf};
    assert_int_equal(tcb_tetrahedralize(&twice, 0.01, 2.0, &t, &err), TCB_ERR_NUMERIC);
    assert_non_null(strstr(err.msg, "failed (signal"));
    assert_null(strchr(err.msg, '\n'));
    /* No program on PATH. */
    const char *path = getenv("PATH");
    char *saved = strdup(path ? path : "");
    setenv("PATH", "/nonexistent", 1);
    assert_int_equal(tcb_tetrahedralize(&shell, 0.01, 2.0, &t, &err), TCB_ERR_UNSUPPORTED);
    assert_non_null(strstr(err.msg, "not on PATH"));
    setenv("PATH", saved, 1);
    free(saved);
    tcb_mesh_free(&shell);
    tcb_mesh_free(&open_box);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_convex_hull),
        cmocka_unit_test(test_convex_offset),
        cmocka_unit_test(test_convex_signed_distance),
        cmocka_unit_test(test_tetrahedralize_cube),
        cmocka_unit_test(test_tetrahedralize_errors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
