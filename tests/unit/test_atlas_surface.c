/* The atlas's textured surface (methods/atlas/surface.c): the UV grid's
 * counts, its layout of vertices in charts, consistently oriented
 * triangles, and that each vertex is its patch's decoder at its (u, v). */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>

#include "methods/atlas/surface.h"
#include "testutil.h"

enum { P = 3, RES = 4, C = 8, N = 24 };

static tcb_uv_mesh grid(int p, int res)
{
    tcb_uv_mesh m;
    tcb_error err = {0};
    assert_int_equal(tcb_atlas_uv_grid(p, res, &m, &err), TCB_OK);
    return m;
}

static void test_counts(void **state)
{
    (void)state;
    tcb_uv_mesh m = grid(P, RES);
    assert_int_equal(m.n_verts, P * RES * RES);
    assert_int_equal(m.n_faces, P * 2 * (RES - 1) * (RES - 1));
    assert_int_equal(m.n_charts, P);
    assert_null(m.verts); /* the grid alone: nothing decoded */
    tcb_uv_mesh_free(&m);
    m = grid(10, TCB_ATLAS_SURFACE_RES);
    assert_int_equal(m.n_faces, 10 * 2 * 24 * 24);
    tcb_uv_mesh_free(&m);
}

/* Vertex p RES² + r RES + c is chart p at (c, r) / (RES − 1). */
static void test_layout(void **state)
{
    (void)state;
    tcb_uv_mesh m = grid(P, RES);
    for (int k = 0; k < m.n_verts; k++) {
        int p = k / (RES * RES), r = k / RES % RES, c = k % RES;
        assert_int_equal(m.chart[k], p);
        assert_near(m.uv[2 * k], (float)c / (RES - 1), 0);
        assert_near(m.uv[2 * k + 1], (float)r / (RES - 1), 0);
    }
    tcb_uv_mesh_free(&m);
}

/* Every face inside one chart, turning left in (u, v), and the faces of a
 * chart tiling its unit square: their areas add up to 1. */
static void test_orientation(void **state)
{
    (void)state;
    tcb_uv_mesh m = grid(P, RES);
    double area[P] = {0};
    for (int f = 0; f < m.n_faces; f++) {
        const int32_t *t = m.faces + 3 * f;
        for (int a = 0; a < 3; a++) assert_true(t[a] >= 0 && t[a] < m.n_verts);
        assert_int_equal(m.chart[t[0]], m.chart[t[1]]);
        assert_int_equal(m.chart[t[0]], m.chart[t[2]]);
        const float *a = m.uv + 2 * t[0], *b = m.uv + 2 * t[1], *c = m.uv + 2 * t[2];
        double cross = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
        assert_true(cross > 0);
        area[m.chart[t[0]]] += cross / 2;
    }
    for (int p = 0; p < P; p++) assert_near(area[p], 1.0, 1e-6);
    tcb_uv_mesh_free(&m);
}

static void test_rejects(void **state)
{
    (void)state;
    tcb_uv_mesh m;
    tcb_error err = {0};
    assert_int_equal(tcb_atlas_uv_grid(0, RES, &m, &err), TCB_ERR_INPUT);
    assert_int_equal(tcb_atlas_uv_grid(P, 1, &m, &err), TCB_ERR_INPUT);
    assert_null(m.uv);
}

/* Vertex (p, r, c) is patch p's decoder at its (u, v): the same point as a
 * forward pass with one sample per patch at that (u, v). */
static void test_decodes_each_patch(void **state)
{
    (void)state;
    tcb_atlas_model *model;
    tcb_error err = {0};
    assert_int_equal(tcb_atlas_model_create(C, P, &model, &err), TCB_OK);
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 3, "test/atlas_surface");
    tcb_atlas_model_init(model, &rng);
    float cloud[N * 3];
    for (int k = 0; k < N * 3; k++) cloud[k] = (float)tcb_rng_uniform(&rng) - 0.5f;
    tcb_uv_mesh m;
    assert_int_equal(tcb_atlas_surface(model, cloud, N, RES, &m, &err), TCB_OK);
    tcb_atlas_work *w;
    assert_int_equal(tcb_atlas_work_create(model, 1, N, P, &w, &err), TCB_OK);
    const int r = 2, c = 1;
    float uv[P * 2], phi[P * 3];
    for (int p = 0; p < P; p++) uv[2 * p] = (float)c / (RES - 1), uv[2 * p + 1] = (float)r / (RES - 1);
    tcb_atlas_model_forward(model, w, cloud, uv, phi, NULL, NULL);
    for (int p = 0; p < P; p++)
        for (int a = 0; a < 3; a++)
            assert_near(m.verts[3 * ((p * RES + r) * RES + c) + a], phi[3 * p + a], 1e-5);
    /* the patches differ: a mix-up of their order would show */
    assert_true(fabsf(phi[0] - phi[3]) + fabsf(phi[1] - phi[4]) + fabsf(phi[2] - phi[5]) > 1e-4f);
    tcb_atlas_work_free(w);
    tcb_uv_mesh_free(&m);
    tcb_atlas_model_free(model);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_counts),       cmocka_unit_test(test_layout),
        cmocka_unit_test(test_orientation),  cmocka_unit_test(test_rejects),
        cmocka_unit_test(test_decodes_each_patch),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
