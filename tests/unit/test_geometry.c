/* Areas, centroids, vertex normals and area-uniform sampling. */
#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>
#include <stdlib.h>
#include <string.h>

#include "tcb/geometry.h"
#include "testutil.h"

/* Unit cube [0,1]^3, vertex i = (i&1, i>>1&1, i>>2&1), 12 outward triangles. */
static const float cube_v[8 * 3] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0,
                                    0, 0, 1, 1, 0, 1, 0, 1, 1, 1, 1, 1};
static const int32_t cube_f[12 * 3] = {0, 4, 6, 0, 6, 2, 1, 3, 7, 1, 7, 5, 0, 1, 5, 0, 5, 4,
                                       2, 6, 7, 2, 7, 3, 0, 2, 3, 0, 3, 1, 4, 5, 7, 4, 7, 6};

/* Regular tetrahedron centred at the origin, edge 2√2, outward faces. */
static const float tet_v[4 * 3] = {1, 1, 1, 1, -1, -1, -1, 1, -1, -1, -1, 1};
static const int32_t tet_f[4 * 3] = {0, 1, 2, 0, 3, 1, 0, 2, 3, 1, 3, 2};

static void test_triangle_area(void **state)
{
    (void)state;
    const float o[3] = {0, 0, 0}, x[3] = {1, 0, 0}, y[3] = {0, 1, 0}, z[3] = {0, 0, 1};
    const float x3[3] = {3, 0, 0}, y4[3] = {0, 4, 0}, x2[3] = {2, 0, 0};
    assert_near(tcb_triangle_area(o, x, y), 0.5, 1e-15);
    assert_near(tcb_triangle_area(o, x3, y4), 6.0, 1e-15);
    assert_near(tcb_triangle_area(x, y, z), sqrt(3.0) / 2.0, 1e-15);
    assert_near(tcb_triangle_area(o, x, x2), 0.0, 0.0); /* collinear */
}

static void test_mesh_area(void **state)
{
    (void)state;
    assert_near(tcb_mesh_area(cube_v, cube_f, 12), 6.0, 1e-12);
    /* four equilateral faces of edge 2√2: 4 · (√3/4) · 8 */
    assert_near(tcb_mesh_area(tet_v, tet_f, 4), 8.0 * sqrt(3.0), 1e-12);
}

static void test_surface_centroid(void **state)
{
    (void)state;
    double c[3];
    tcb_surface_centroid(cube_v, cube_f, 12, c);
    for (int d = 0; d < 3; d++) assert_near(c[d], 0.5, 1e-12);
    /* Two triangles: area 0.5 with centroid (1/3,1/3,0) and area 2 with
     * centroid (2/3,2/3,5): weights 1/5 and 4/5. */
    const float v[6 * 3] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 5, 2, 0, 5, 0, 2, 5};
    const int32_t f[2 * 3] = {0, 1, 2, 3, 4, 5};
    tcb_surface_centroid(v, f, 2, c);
    assert_near(c[0], 0.2 / 3.0 + 0.8 * 2.0 / 3.0, 1e-12);
    assert_near(c[1], 0.2 / 3.0 + 0.8 * 2.0 / 3.0, 1e-12);
    assert_near(c[2], 4.0, 1e-12);
}

static void test_normals_tetra(void **state)
{
    (void)state;
    /* Each vertex touches three equal faces, so its normal points away
     * from the centre along the vertex itself. */
    float n[4 * 3];
    tcb_vertex_normals(tet_v, 4, tet_f, 4, n);
    for (int i = 0; i < 4; i++)
        for (int d = 0; d < 3; d++) assert_float_equal(n[3 * i + d], tet_v[3 * i + d] / sqrtf(3.0f), 1e-6);
}

static void test_normals_cube(void **state)
{
    (void)state;
    /* Vertex 8 lies on no face; its normal must be zero. */
    float v[9 * 3], n[9 * 3];
    memcpy(v, cube_v, sizeof cube_v);
    v[24] = v[25] = v[26] = 7.0f;
    tcb_vertex_normals(v, 9, cube_f, 12, n);
    for (int i = 0; i < 8; i++) {
        const float *p = n + 3 * i;
        assert_float_equal(p[0] * p[0] + p[1] * p[1] + p[2] * p[2], 1.0f, 1e-6);
        for (int d = 0; d < 3; d++) { /* every component points outward */
            float out = cube_v[3 * i + d] - 0.5f;
            assert_true(p[d] * out > 0.1f);
        }
    }
    assert_true(n[24] == 0.0f && n[25] == 0.0f && n[26] == 0.0f);
}

/* p lies inside some triangle iff its three sub-triangle areas add up to
 * that triangle's area (off the plane or outside, the sum is larger). */
static int on_surface(const float *v, const int32_t *f, int nf, const float *p)
{
    for (int i = 0; i < nf; i++) {
        const float *a = v + 3 * f[3 * i], *b = v + 3 * f[3 * i + 1], *c = v + 3 * f[3 * i + 2];
        double whole = tcb_triangle_area(a, b, c);
        double parts = tcb_triangle_area(p, b, c) + tcb_triangle_area(a, p, c) + tcb_triangle_area(a, b, p);
        if (fabs(parts - whole) <= 1e-5 * (1.0 + whole)) return 1;
    }
    return 0;
}

static void test_sampling_deterministic_and_on_surface(void **state)
{
    (void)state;
    enum { N = 2000 };
    float *a = malloc(sizeof(float) * 3 * N), *b = malloc(sizeof(float) * 3 * N);
    tcb_rng r;
    tcb_rng_seed(&r, 42);
    assert_int_equal(tcb_sample_surface(tet_v, tet_f, 4, N, &r, a, NULL), TCB_OK);
    tcb_rng_seed(&r, 42);
    assert_int_equal(tcb_sample_surface(tet_v, tet_f, 4, N, &r, b, NULL), TCB_OK);
    assert_memory_equal(a, b, sizeof(float) * 3 * N);
    for (int i = 0; i < N; i++) assert_true(on_surface(tet_v, tet_f, 4, a + 3 * i));
    tcb_rng_seed(&r, 43);
    assert_int_equal(tcb_sample_surface(tet_v, tet_f, 4, N, &r, b, NULL), TCB_OK);
    assert_memory_not_equal(a, b, sizeof(float) * 3 * N);
    free(a);
    free(b);
}

/* |count − n·p| within 5 binomial standard deviations: for a fresh seed
 * this fails with probability < 1e-6; the fixed seed makes it exact. */
static void assert_binomial(int count, int n, double p)
{
    double sd = sqrt(n * p * (1.0 - p));
    assert_true(fabs(count - n * p) <= 5.0 * sd);
}

static void test_sampling_face_frequencies(void **state)
{
    (void)state;
    /* Right triangles of areas 1, 2, 3, 4 in the planes z = 1..4, and a
     * degenerate one at z = 9 that must never be chosen. */
    float v[15 * 3];
    int32_t f[5 * 3];
    for (int k = 0; k < 5; k++) {
        float leg = k < 4 ? sqrtf(2.0f * (k + 1)) : 0.0f, z = k < 4 ? (float)(k + 1) : 9.0f;
        float tri[9] = {0, 0, z, leg, 0, z, 0, leg, z};
        memcpy(v + 9 * k, tri, sizeof tri);
        for (int j = 0; j < 3; j++) f[3 * k + j] = 3 * k + j;
    }
    enum { N = 100000 };
    float *p = malloc(sizeof(float) * 3 * N);
    tcb_rng r;
    tcb_rng_seed(&r, 7);
    assert_int_equal(tcb_sample_surface(v, f, 5, N, &r, p, NULL), TCB_OK);
    int count[10] = {0}, near_corner = 0, on_first = 0;
    for (int i = 0; i < N; i++) {
        int z = (int)lrintf(p[3 * i + 2]);
        assert_true(z >= 1 && z <= 9);
        count[z]++;
        if (z == 1) { /* triangle 1 has legs √2; x + y < √2/2 is a quarter of it */
            on_first++;
            near_corner += p[3 * i] + p[3 * i + 1] < sqrtf(2.0f) / 2.0f;
        }
    }
    for (int k = 1; k <= 4; k++) assert_binomial(count[k], N, k / 10.0);
    assert_int_equal(count[9], 0);
    /* The sqrt trick makes the barycentric point uniform; without it the
     * corner quarter would receive half the samples. */
    assert_binomial(near_corner, on_first, 0.25);
    free(p);
}

static void test_sampling_zero_area_fails(void **state)
{
    (void)state;
    const float v[9] = {0, 0, 0, 1, 0, 0, 2, 0, 0};
    const int32_t f[3] = {0, 1, 2};
    float out[3];
    tcb_rng r;
    tcb_rng_seed(&r, 1);
    tcb_error err = {0};
    assert_int_equal(tcb_sample_surface(v, f, 1, 1, &r, out, &err), TCB_ERR_INPUT);
    assert_non_null(strstr(err.msg, "area"));
}

/* The box of a 3 x 4 x 12 cuboid's corners and a point inside: diagonal 13. */
static void test_bbox(void **state)
{
    (void)state;
    const float pts[] = {1, -2, 5, 4, 2, -7, 2, 0, 0, 1, 2, 5};
    double box[6];
    tcb_bbox(pts, 4, box);
    const double want[6] = {1, -2, -7, 4, 2, 5};
    for (int k = 0; k < 6; k++) assert_float_equal(box[k], want[k], 0);
    assert_float_equal(tcb_bbox_diag(box), 13.0, 1e-12);
}

/* Farthest points on a line of ten: 0 first, then the far end, then the
 * first of the two middle points; on a random cloud every chosen point is
 * as far from the earlier ones as any unchosen point is (the greedy rule),
 * and no point is chosen twice. */
static void test_farthest_points(void **state)
{
    (void)state;
    float line[30] = {0};
    for (int i = 0; i < 10; i++) line[3 * i] = (float)i;
    int32_t idx[4];
    tcb_error err = {0};
    assert_int_equal(tcb_farthest_points(line, 10, 4, 0, idx, &err), TCB_OK);
    assert_int_equal(idx[0], 0);
    assert_int_equal(idx[1], 9);
    assert_int_equal(idx[2], 4);
    assert_int_equal(idx[3], 2); /* 2 and 7 both 2 from {0, 4, 9}: the first */
    enum { N = 300, K = 30 };
    float p[3 * N];
    tcb_rng rng;
    tcb_rng_seed(&rng, 5);
    for (int i = 0; i < 3 * N; i++) p[i] = (float)tcb_rng_uniform(&rng);
    int32_t pick[K];
    assert_int_equal(tcb_farthest_points(p, N, K, 17, pick, &err), TCB_OK);
    assert_int_equal(pick[0], 17);
    for (int c = 1; c < K; c++) {
        double far = -1, chosen = 0;
        for (int i = 0; i < N; i++) {
            double near = INFINITY;
            for (int e = 0; e < c; e++) {
                double d = 0;
                for (int x = 0; x < 3; x++) d += ((double)p[3 * i + x] - p[3 * pick[e] + x]) * ((double)p[3 * i + x] - p[3 * pick[e] + x]);
                near = d < near ? d : near;
            }
            far = near > far ? near : far;
            if (i == pick[c]) chosen = near;
        }
        assert_true(chosen > 0 && fabs(chosen - far) <= 1e-6 * far);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_triangle_area),
        cmocka_unit_test(test_bbox),
        cmocka_unit_test(test_mesh_area),
        cmocka_unit_test(test_surface_centroid),
        cmocka_unit_test(test_normals_tetra),
        cmocka_unit_test(test_normals_cube),
        cmocka_unit_test(test_sampling_deterministic_and_on_surface),
        cmocka_unit_test(test_sampling_face_frequencies),
        cmocka_unit_test(test_sampling_zero_area_fails),
        cmocka_unit_test(test_farthest_points),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
