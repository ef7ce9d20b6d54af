/* Closest surface points by face and barycentric weights (tcb/locate.h):
 * the Voronoi cases of one triangle, agreement with a brute force over a
 * triangle soup of very unequal sizes (so the centroid pruning of several
 * radius classes is tested where it is tight), exact ties across those
 * classes, carrying points to an affine image of the mesh, and bad input. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bent_tube.h"
#include "tcb/geometry.h"
#include "tcb/locate.h"
#include "tcb/rng.h"
#include "testutil.h"

static void locate_ok(const float *v, int nv, const int32_t *f, int nf, const float *q, int nq,
                      tcb_surface_point *loc, float *d2)
{
    tcb_error err = {0};
    int rc = tcb_mesh_locate(v, nv, f, nf, q, nq, loc, d2, &err);
    if (rc) fail_msg("locate: %s", err.msg);
}

static void test_one_triangle(void **state)
{
    (void)state;
    const float v[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    const int32_t f[3] = {0, 1, 2};
    /* above the face, beyond vertex 0, beyond edge 01, beyond edge 12 */
    const float q[12] = {0.2f, 0.3f, 5, -1, -1, 0, 0.5f, -2, 1, 1, 1, 0};
    const double bary[4][3] = {{0.5, 0.2, 0.3}, {1, 0, 0}, {0.5, 0.5, 0}, {0, 0.5, 0.5}};
    const double dist2[4] = {25, 2, 5, 0.5};
    tcb_surface_point loc[4];
    float d2[4];
    locate_ok(v, 3, f, 1, q, 4, loc, d2);
    for (int i = 0; i < 4; i++) {
        assert_int_equal(loc[i].face, 0);
        for (int k = 0; k < 3; k++) assert_near(loc[i].bary[k], bary[i][k], 1e-6);
        assert_near(d2[i], dist2[i], 1e-5);
    }
}

/* ---- the reference: a brute force by another construction --------------- */

static double dot(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/* Squared distance from p to segment a–b. */
static double segment_d2(const double *p, const double *a, const double *b)
{
    double e[3], r[3];
    for (int d = 0; d < 3; d++) e[d] = b[d] - a[d], r[d] = p[d] - a[d];
    double s = dot(e, e) > 0 ? fmin(1, fmax(0, dot(r, e) / dot(e, e))) : 0;
    for (int d = 0; d < 3; d++) r[d] -= s * e[d];
    return dot(r, r);
}

/* The projection onto the plane when it falls inside (barycentric weights
 * from the 2×2 normal equations), else the nearest of the three edges. */
static double triangle_d2(const double *p, const double *a, const double *b, const double *c)
{
    double e1[3], e2[3], r[3];
    for (int d = 0; d < 3; d++) e1[d] = b[d] - a[d], e2[d] = c[d] - a[d], r[d] = p[d] - a[d];
    double g11 = dot(e1, e1), g12 = dot(e1, e2), g22 = dot(e2, e2), det = g11 * g22 - g12 * g12;
    if (det > 1e-12 * g11 * g22) {
        double s = (g22 * dot(r, e1) - g12 * dot(r, e2)) / det, t = (g11 * dot(r, e2) - g12 * dot(r, e1)) / det;
        if (s >= 0 && t >= 0 && s + t <= 1) {
            for (int d = 0; d < 3; d++) r[d] -= s * e1[d] + t * e2[d];
            return dot(r, r);
        }
    }
    return fmin(segment_d2(p, a, b), fmin(segment_d2(p, b, c), segment_d2(p, c, a)));
}

static double brute_d2(const float *v, const int32_t *f, int nf, const float *qf)
{
    double best = INFINITY, p[3] = {qf[0], qf[1], qf[2]};
    for (int t = 0; t < nf; t++) {
        double x[3][3];
        for (int k = 0; k < 3; k++)
            for (int d = 0; d < 3; d++) x[k][d] = v[3 * f[3 * t + k] + d];
        best = fmin(best, triangle_d2(p, x[0], x[1], x[2]));
    }
    return best;
}

/* 300 triangles in [-1, 1]^3 with sizes from 0.02 to 1 (log-uniform), one
 * with a repeated vertex, one with collinear vertices and one nearly so; 2 000 queries in
 * [-1.5, 1.5]^3. */
static void test_matches_brute_force(void **state)
{
    (void)state;
    enum { NF = 300, NQ = 2000 };
    tcb_rng r;
    tcb_rng_seed(&r, 11);
    float *v = tu_falloc(9 * NF), *q = tu_falloc(3 * NQ), d2[NQ], pts[3 * NQ];
    int32_t f[3 * NF];
    for (int t = 0; t < NF; t++) {
        double size = exp(log(0.02) * tcb_rng_uniform(&r));
        for (int d = 0; d < 3; d++) {
            double c = 2 * tcb_rng_uniform(&r) - 1;
            for (int k = 0; k < 3; k++) v[9 * t + 3 * k + d] = (float)(c + size * (tcb_rng_uniform(&r) - 0.5));
        }
        for (int k = 0; k < 3; k++) f[3 * t + k] = 3 * t + k;
    }
    memcpy(v + 9 * 0 + 3, v + 9 * 0, 3 * sizeof(float)); /* triangle 0: vertex 1 = vertex 0 */
    for (int d = 0; d < 3; d++) v[9 * 1 + 6 + d] = 0.5f * (v[9 * 1 + d] + v[9 * 1 + 3 + d]); /* 1: collinear */
    for (int d = 0; d < 3; d++) v[9 * 2 + 6 + d] = 0.3f * v[9 * 2 + d] + 0.7f * v[9 * 2 + 3 + d]; /* 2: nearly */
    tu_fill_uniform(&r, q, 3 * NQ, -1.5, 1.5);
    tcb_surface_point *loc = malloc(NQ * sizeof *loc);
    assert_non_null(loc);
    locate_ok(v, 3 * NF, f, NF, q, NQ, loc, d2);
    tcb_surface_points(v, f, loc, NQ, pts);
    double worst = 0;
    for (int i = 0; i < NQ; i++) {
        double ref = brute_d2(v, f, NF, q + 3 * i), e2 = 0;
        worst = fmax(worst, fabs(d2[i] - ref));
        if (!(fabs(d2[i] - ref) <= 1e-5 * (1 + ref))) fail_msg("query %d: %.9g, brute force %.9g", i, d2[i], ref);
        /* The weights name the point at that distance. */
        for (int d = 0; d < 3; d++) e2 += (q[3 * i + d] - pts[3 * i + d]) * (q[3 * i + d] - pts[3 * i + d]);
        assert_near(e2, d2[i], 1e-5 * (1 + ref));
        const float *w = loc[i].bary;
        assert_true(w[0] >= 0 && w[1] >= 0 && w[2] >= 0);
        assert_near(w[0] + w[1] + w[2], 1.0, 1e-6);
    }
    print_message("locate vs brute force: largest |d2 difference| %.3g over %d queries\n", worst, NQ);
    free(loc);
    free(q);
    free(v);
}

/* Exact ties go to the lowest face index whatever the faces' sizes: four
 * triangles of sizes 10, 0.01, 1 and 0.1 (four radius classes, the
 * smallest searched first) share the vertex at the origin, which is the
 * closest point of each to (−1, −1, −1) at the same squared distance 3. */
static void test_ties_across_size_classes(void **state)
{
    (void)state;
    static const float size[] = {10, 0.01f, 1, 0.1f};
    float v[3 + 3 * 2 * 4] = {0, 0, 0};
    int32_t f[3 * 4];
    for (int t = 0; t < 4; t++) {
        float *a = v + 3 + 6 * t, *b = a + 3;
        a[0] = size[t], a[1] = 0, a[2] = 0.001f * t; /* distinct triangles, all off −x, −y, −z */
        b[0] = 0, b[1] = size[t], b[2] = 0.001f * t;
        f[3 * t] = 0, f[3 * t + 1] = 1 + 2 * t, f[3 * t + 2] = 2 + 2 * t;
    }
    const float q[3] = {-1, -1, -1};
    tcb_surface_point loc;
    float d2;
    locate_ok(v, 9, f, 4, q, 1, &loc, &d2);
    assert_int_equal(loc.face, 0);
    assert_true(d2 == 3.0f);
    assert_true(loc.bary[0] == 1.0f);
}

/* Located on a bent tube, carried to an affine image of it: every point
 * lands on the image of its located point. */
static void test_carry_affine(void **state)
{
    (void)state;
    enum { RINGS = 20, SEGS = 24, NQ = 500 };
    int nv = bent_tube_verts(RINGS, SEGS), nf = bent_tube_faces(RINGS, SEGS);
    float *v = tu_falloc(3 * (size_t)nv), *w = tu_falloc(3 * (size_t)nv), *q = tu_falloc(3 * NQ);
    int32_t *f = malloc(3 * (size_t)nf * sizeof *f);
    assert_non_null(f);
    bent_tube(RINGS, SEGS, 6.0, 2.0, 0.2, 5, v, f);
    tcb_rng r;
    tcb_rng_seed(&r, 12);
    tcb_error err = {0};
    assert_int_equal(tcb_sample_surface(v, f, nf, NQ, &r, q, &err), TCB_OK);
    float noisy[3 * NQ];
    for (int i = 0; i < 3 * NQ; i++) noisy[i] = q[i] + 0.05f * (float)tcb_rng_normal(&r);
    const double A[3][3] = {{0.8, 0.3, 0}, {-0.2, 1.1, 0.1}, {0.05, 0, 1.4}}, t[3] = {0.5, -1, 2};
    for (int k = 0; k < nv; k++)
        for (int d = 0; d < 3; d++)
            w[3 * k + d] = (float)(A[d][0] * v[3 * k] + A[d][1] * v[3 * k + 1] + A[d][2] * v[3 * k + 2] + t[d]);
    tcb_surface_point loc[NQ];
    float d2[NQ], on_v[3 * NQ], on_w[3 * NQ];
    /* Points on the surface are found where they are. */
    locate_ok(v, nv, f, nf, q, NQ, loc, d2);
    tcb_surface_points(v, f, loc, NQ, on_v);
    for (int i = 0; i < 3 * NQ; i++) assert_near(on_v[i], q[i], 1e-5);
    locate_ok(v, nv, f, nf, noisy, NQ, loc, d2);
    tcb_surface_points(v, f, loc, NQ, on_v);
    tcb_surface_points(w, f, loc, NQ, on_w);
    for (int i = 0; i < NQ; i++) {
        const float *p = on_v + 3 * i;
        for (int d = 0; d < 3; d++)
            assert_near(on_w[3 * i + d], A[d][0] * p[0] + A[d][1] * p[1] + A[d][2] * p[2] + t[d], 1e-5);
    }
    free(f);
    free(q);
    free(w);
    free(v);
}

static void test_bad_input(void **state)
{
    (void)state;
    float v[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0}, q[3] = {0, 0, 1};
    int32_t f[3] = {0, 1, 3};
    tcb_surface_point loc;
    tcb_error err = {0};
    assert_int_equal(tcb_mesh_locate(v, 3, f, 1, q, 1, &loc, NULL, &err), TCB_ERR_INPUT);
    assert_non_null(strstr(err.msg, "face 0 names vertex 3 of 3"));
    f[2] = 2;
    assert_int_equal(tcb_mesh_locate(v, 3, f, 0, q, 1, &loc, NULL, &err), TCB_ERR_INPUT);
    assert_non_null(strstr(err.msg, "empty"));
    q[1] = NAN;
    assert_int_equal(tcb_mesh_locate(v, 3, f, 1, q, 1, &loc, NULL, &err), TCB_ERR_NUMERIC);
    assert_non_null(strstr(err.msg, "query coordinate"));
    q[1] = 0;
    v[4] = INFINITY;
    assert_int_equal(tcb_mesh_locate(v, 3, f, 1, q, 1, &loc, NULL, &err), TCB_ERR_NUMERIC);
    assert_non_null(strstr(err.msg, "vertex coordinate"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_one_triangle),
        cmocka_unit_test(test_matches_brute_force),
        cmocka_unit_test(test_ties_across_size_classes),
        cmocka_unit_test(test_carry_affine),
        cmocka_unit_test(test_bad_input),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
