/* OBJ directories, normalization, point pools and input draws. */
#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tcb/fsutil.h"
#include "tcb/geometry.h"
#include "tcb/sequence.h"
#include "testutil.h"

/* An irregular tetrahedron: its vertex mean and surface centroid differ. */
static const float base_v[4 * 3] = {0, 0, 0, 2, 0, 0, 0, 1, 0, 0, 0, 3};
static const int32_t base_f[4 * 3] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};

enum { EXTRA_VERTEX = 1, OTHER_FACES = 2 };

/* Writes dir/name: the base shape scaled by `scale` and moved by (dx, 1, 2). */
static void write_frame(const char *dir, const char *name, float scale, float dx, int flags)
{
    char text[1024], path[TCB_PATH_MAX];
    int n = 0;
    for (int i = 0; i < 4; i++)
        n += snprintf(text + n, sizeof text - (size_t)n, "v %.9g %.9g %.9g\n", scale * base_v[3 * i] + dx,
                      scale * base_v[3 * i + 1] + 1.0f, scale * base_v[3 * i + 2] + 2.0f);
    if (flags & EXTRA_VERTEX) n += snprintf(text + n, sizeof text - (size_t)n, "v 9 9 9\n");
    for (int i = 0; i < 4; i++) {
        const int32_t *f = base_f + 3 * ((flags & OTHER_FACES) ? 3 - i : i);
        n += snprintf(text + n, sizeof text - (size_t)n, "f %d %d %d\n", f[0] + 1, f[1] + 1, f[2] + 1);
    }
    tu_write_text(dir, name, text, path, sizeof path);
}

/* x of vertex 0 in frame f: write_frame puts it at dx. */
static float frame_dx(const tcb_sequence *s, int f) { return tcb_seq_frame(s, f)[0]; }

static void test_order_by_last_number(void **state)
{
    const char *dir = *state;
    write_frame(dir, "mesh.2.obj", 1, 2, 0);
    write_frame(dir, "mesh.10.obj", 1, 10, 0);
    write_frame(dir, "mesh.1.obj", 1, 1, 0);
    char path[TCB_PATH_MAX];
    tu_write_text(dir, "notes.txt", "not a frame", path, sizeof path);
    tcb_sequence s;
    tcb_error err = {0};
    assert_int_equal(tcb_sequence_read_objdir(dir, &s, &err), TCB_OK);
    assert_int_equal(s.n_frames, 3);
    assert_int_equal(s.n_verts, 4);
    assert_int_equal(s.n_faces, 4);
    assert_memory_equal(s.faces, base_f, sizeof base_f);
    assert_true(frame_dx(&s, 0) == 1.0f && frame_dx(&s, 1) == 2.0f && frame_dx(&s, 2) == 10.0f);
    const char *base = strrchr(dir, '/') + 1;
    assert_string_equal(s.name, base);
    tcb_sequence_free(&s);
}

static void test_order_zero_padded(void **state)
{
    const char *dir = *state;
    for (int k = 11; k >= 0; k--) {
        char name[64];
        snprintf(name, sizeof name, "take2_mesh_%04d.obj", k); /* "2" is not the frame number */
        write_frame(dir, name, 1, (float)k, 0);
    }
    tcb_sequence s;
    tcb_error err = {0};
    assert_int_equal(tcb_sequence_read_objdir(dir, &s, &err), TCB_OK);
    assert_int_equal(s.n_frames, 12);
    for (int f = 0; f < 12; f++) assert_true(frame_dx(&s, f) == (float)f);
    tcb_sequence_free(&s);
}

static void expect_input_error(const char *dir, const char *part1, const char *part2)
{
    tcb_sequence s;
    tcb_error err = {0};
    assert_int_equal(tcb_sequence_read_objdir(dir, &s, &err), TCB_ERR_INPUT);
    if (!strstr(err.msg, part1) || (part2 && !strstr(err.msg, part2)))
        fail_msg("'%s' should name '%s' and '%s'", err.msg, part1, part2 ? part2 : "");
    assert_null(s.verts);
}

static void test_same_number_is_an_error(void **state)
{
    write_frame(*state, "mesh.1.obj", 1, 0, 0);
    write_frame(*state, "mesh.01.obj", 1, 0, 0);
    write_frame(*state, "mesh.2.obj", 1, 0, 0);
    expect_input_error(*state, "mesh.1.obj", "mesh.01.obj");
}

static void test_name_without_number_is_an_error(void **state)
{
    write_frame(*state, "mesh.1.obj", 1, 0, 0);
    write_frame(*state, "rest_pose.obj", 1, 0, 0);
    expect_input_error(*state, "rest_pose.obj", NULL);
}

static void test_vertex_count_mismatch_names_both(void **state)
{
    char first[TCB_PATH_MAX], second[TCB_PATH_MAX];
    write_frame(*state, "mesh_01.obj", 1, 0, 0);
    write_frame(*state, "mesh_02.obj", 1, 0, EXTRA_VERTEX);
    snprintf(first, sizeof first, "%s/mesh_01.obj", (const char *)*state);
    snprintf(second, sizeof second, "%s/mesh_02.obj", (const char *)*state);
    expect_input_error(*state, first, second);
}

static void test_face_mismatch_names_both(void **state)
{
    char first[TCB_PATH_MAX], second[TCB_PATH_MAX];
    write_frame(*state, "mesh_01.obj", 1, 0, 0);
    write_frame(*state, "mesh_02.obj", 1, 0, 0);
    write_frame(*state, "mesh_03.obj", 1, 0, OTHER_FACES);
    snprintf(first, sizeof first, "%s/mesh_01.obj", (const char *)*state);
    snprintf(second, sizeof second, "%s/mesh_03.obj", (const char *)*state);
    expect_input_error(*state, first, second);
}

static void test_too_few_frames(void **state)
{
    const char *dir = *state;
    expect_input_error(dir, dir, NULL); /* empty: names the directory */
    write_frame(dir, "mesh.1.obj", 1, 0, 0);
    expect_input_error(dir, "mesh.1.obj", NULL);
    char missing[TCB_PATH_MAX];
    snprintf(missing, sizeof missing, "%s/absent", dir);
    tcb_sequence s;
    tcb_error err = {0};
    assert_int_equal(tcb_sequence_read_objdir(missing, &s, &err), TCB_ERR_IO);
    assert_non_null(strstr(err.msg, missing));
}

/* Three frames: the base shape, ×2 moved, ×0.5 moved. */
static void read_three(const char *dir, tcb_sequence *s)
{
    write_frame(dir, "f1.obj", 1, 0, 0);
    write_frame(dir, "f2.obj", 2, 5, 0);
    write_frame(dir, "f3.obj", 0.5f, -3, 0);
    tcb_error err = {0};
    assert_int_equal(tcb_sequence_read_objdir(dir, s, &err), TCB_OK);
}

static void test_first_frame_normalization(void **state)
{
    tcb_sequence s, raw;
    read_three(*state, &s);
    read_three(*state, &raw);
    tcb_error err = {0};
    assert_int_equal(tcb_sequence_normalize(&s, TCB_NORM_FIRST_FRAME, &err), TCB_OK);
    assert_int_equal(s.norm, TCB_NORM_FIRST_FRAME);
    /* Frame 0 raw: vertex mean (0.5, 1.25, 2.75), extents 2, 1, 3. */
    assert_near(s.norm_scale, 3.0, 0.0);
    const double c[3] = {0.5, 1.25, 2.75};
    double mean[3] = {0, 0, 0}, lo[3] = {1e9, 1e9, 1e9}, hi[3] = {-1e9, -1e9, -1e9};
    for (int i = 0; i < 4; i++)
        for (int d = 0; d < 3; d++) {
            double x = tcb_seq_frame(&s, 0)[3 * i + d];
            mean[d] += x / 4;
            lo[d] = fmin(lo[d], x);
            hi[d] = fmax(hi[d], x);
        }
    double extent = 0;
    for (int d = 0; d < 3; d++) {
        assert_near(mean[d], 0.0, 1e-7);
        extent = fmax(extent, hi[d] - lo[d]);
    }
    assert_near(extent, 1.0, 1e-7);
    for (int f = 0; f < 3; f++) {
        for (int d = 0; d < 3; d++) assert_near(s.norm_shift[3 * f + d], c[d], 1e-12);
        for (int i = 0; i < 12; i++) /* the same transform applies to every frame */
            assert_near(tcb_seq_frame(&s, f)[i], (tcb_seq_frame(&raw, f)[i] - c[i % 3]) / 3.0, 1e-6);
        double raw_area = tcb_mesh_area(tcb_seq_frame(&raw, f), raw.faces, raw.n_faces);
        assert_near(s.areas[f], raw_area / 9.0, 1e-6 * raw_area);
    }
    tcb_sequence_free(&s);
    tcb_sequence_free(&raw);
}

static void test_per_frame_normalization(void **state)
{
    tcb_sequence s, raw;
    read_three(*state, &s);
    read_three(*state, &raw);
    tcb_error err = {0};
    assert_int_equal(tcb_sequence_normalize(&s, TCB_NORM_PER_FRAME, &err), TCB_OK);
    assert_near(s.norm_scale, 1.0, 0.0);
    for (int f = 0; f < 3; f++) {
        double c[3], c_raw[3];
        tcb_surface_centroid(tcb_seq_frame(&s, f), s.faces, s.n_faces, c);
        tcb_surface_centroid(tcb_seq_frame(&raw, f), raw.faces, raw.n_faces, c_raw);
        for (int d = 0; d < 3; d++) {
            assert_near(c[d], 0.0, 1e-6);
            assert_near(s.norm_shift[3 * f + d], c_raw[d], 1e-12);
        }
        double raw_area = tcb_mesh_area(tcb_seq_frame(&raw, f), raw.faces, raw.n_faces);
        assert_near(s.areas[f], raw_area, 1e-6 * raw_area);
    }
    tcb_sequence_free(&s);
    tcb_sequence_free(&raw);
}

static void test_no_normalization(void **state)
{
    tcb_sequence s, raw;
    read_three(*state, &s);
    read_three(*state, &raw);
    tcb_error err = {0};
    assert_int_equal(tcb_sequence_normalize(&s, TCB_NORM_NONE, &err), TCB_OK);
    assert_memory_equal(s.verts, raw.verts, sizeof(float) * 3 * 4 * 3);
    for (int i = 0; i < 9; i++) assert_true(s.norm_shift[i] == 0.0);
    assert_near(s.areas[1], tcb_mesh_area(tcb_seq_frame(&raw, 1), raw.faces, raw.n_faces), 0.0);
    /* Pools exist now, so normalizing again would leave them stale. */
    assert_int_equal(tcb_sequence_sample_pools(&s, 8, 1, &err), TCB_OK);
    assert_int_equal(tcb_sequence_normalize(&s, TCB_NORM_FIRST_FRAME, &err), TCB_ERR_INTERNAL);
    tcb_sequence_free(&s);
    tcb_sequence_free(&raw);
}

static size_t pools_bytes(const tcb_sequence *s)
{
    return sizeof(float) * 3 * (size_t)s->n_frames * (size_t)s->pool_size;
}

static void test_pools_deterministic_and_seeded(void **state)
{
    tcb_sequence a, b;
    tcb_error err = {0};
    read_three(*state, &a);
    read_three(*state, &b);
    assert_int_equal(tcb_sequence_sample_pools(&a, 100, 5, &err), TCB_OK);
    assert_int_equal(tcb_sequence_sample_pools(&b, 100, 5, &err), TCB_OK);
    assert_int_equal(a.pool_size, 100);
    assert_memory_equal(a.pools, b.pools, pools_bytes(&a));
    assert_int_equal(tcb_sequence_sample_pools(&b, 100, 6, &err), TCB_OK); /* resample replaces */
    assert_memory_not_equal(a.pools, b.pools, pools_bytes(&a));
    /* The name is part of the stream label. */
    strcpy(b.name, "other");
    assert_int_equal(tcb_sequence_sample_pools(&b, 100, 5, &err), TCB_OK);
    assert_memory_not_equal(a.pools, b.pools, pools_bytes(&a));
    /* Frames are independent: a two-frame prefix has the same pools. */
    tcb_sequence p;
    assert_int_equal(tcb_sequence_alloc(&p, a.name, 2, a.n_verts, a.n_faces, &err), TCB_OK);
    memcpy(p.verts, a.verts, sizeof(float) * 3 * 2 * (size_t)a.n_verts);
    memcpy(p.faces, a.faces, sizeof(int32_t) * 3 * (size_t)a.n_faces);
    assert_int_equal(tcb_sequence_sample_pools(&p, 100, 5, &err), TCB_OK);
    assert_memory_equal(p.pools, a.pools, pools_bytes(&p));
    assert_int_equal(tcb_sequence_sample_pools(&p, 0, 5, &err), TCB_ERR_INPUT);
    tcb_sequence_free(&p);
    tcb_sequence_free(&a);
    tcb_sequence_free(&b);
}

/* Index of point q in frame f's pool (pool points are distinct). */
static int pool_index(const tcb_sequence *s, int f, const float *q)
{
    for (int k = 0; k < s->pool_size; k++)
        if (memcmp(tcb_seq_pool(s, f) + 3 * k, q, 3 * sizeof(float)) == 0) return k;
    return -1;
}

static void test_draw_without_replacement(void **state)
{
    enum { P = 64 };
    tcb_sequence s;
    tcb_error err = {0};
    read_three(*state, &s);
    assert_int_equal(tcb_sequence_sample_pools(&s, P, 1, &err), TCB_OK);
    float out[3 * P], again[3 * P];
    tcb_rng r;
    tcb_rng_seed(&r, 9);
    assert_int_equal(tcb_sequence_draw_points(&s, 2, P, 0, &r, out, &err), TCB_OK);
    int seen[P] = {0};
    for (int i = 0; i < P; i++) { /* all of the pool, each point once */
        int k = pool_index(&s, 2, out + 3 * i);
        assert_true(k >= 0);
        seen[k]++;
    }
    for (int k = 0; k < P; k++) assert_int_equal(seen[k], 1);
    tcb_rng_seed(&r, 9);
    assert_int_equal(tcb_sequence_draw_points(&s, 2, 20, 0, &r, again, &err), TCB_OK);
    assert_memory_equal(again, out, sizeof(float) * 3 * 20); /* a prefix of the same permutation */
    assert_int_equal(tcb_sequence_draw_points(&s, 2, P + 1, 0, &r, out, &err), TCB_ERR_INPUT);
    assert_int_equal(tcb_sequence_draw_points(&s, 3, 1, 0, &r, out, &err), TCB_ERR_INPUT);
    tcb_sequence_free(&s);
}

static void test_draw_with_replacement(void **state)
{
    enum { P = 16, N = 64 };
    tcb_sequence s;
    tcb_error err = {0};
    read_three(*state, &s);
    assert_int_equal(tcb_sequence_sample_pools(&s, P, 1, &err), TCB_OK);
    float out[3 * N];
    tcb_rng r;
    tcb_rng_seed(&r, 3);
    assert_int_equal(tcb_sequence_draw_points(&s, 1, N, 1, &r, out, &err), TCB_OK);
    int seen[P] = {0}, repeats = 0;
    for (int i = 0; i < N; i++) {
        int k = pool_index(&s, 1, out + 3 * i);
        assert_true(k >= 0);
        repeats += seen[k]++ > 0;
    }
    assert_true(repeats >= N - P); /* more draws than points: repeats are forced */
    tcb_sequence_free(&s);
}

static void test_write_objdir_round_trip(void **state)
{
    tcb_sequence s, back;
    tcb_error err = {0};
    read_three(*state, &s);
    assert_int_equal(tcb_sequence_normalize(&s, TCB_NORM_FIRST_FRAME, &err), TCB_OK);
    char out[TCB_PATH_MAX];
    snprintf(out, sizeof out, "%s/export/walk", (const char *)*state);
    assert_int_equal(tcb_sequence_write_objdir(&s, out, &err), TCB_OK);
    assert_int_equal(tcb_sequence_read_objdir(out, &back, &err), TCB_OK);
    assert_string_equal(back.name, "walk");
    assert_int_equal(back.n_frames, 3);
    assert_memory_equal(back.verts, s.verts, sizeof(float) * 3 * 4 * 3);
    assert_memory_equal(back.faces, s.faces, sizeof(int32_t) * 3 * 4);
    tcb_sequence_free(&s);
    tcb_sequence_free(&back);
}

int main(void)
{
#define T(f) cmocka_unit_test_setup_teardown(f, tu_setup_tmpdir, tu_teardown_tmpdir)
    const struct CMUnitTest tests[] = {
        T(test_order_by_last_number),
        T(test_order_zero_padded),
        T(test_same_number_is_an_error),
        T(test_name_without_number_is_an_error),
        T(test_vertex_count_mismatch_names_both),
        T(test_face_mismatch_names_both),
        T(test_too_few_frames),
        T(test_first_frame_normalization),
        T(test_per_frame_normalization),
        T(test_no_normalization),
        T(test_pools_deterministic_and_seeded),
        T(test_draw_without_replacement),
        T(test_draw_with_replacement),
        T(test_write_objdir_round_trip),
    };
#undef T
    return cmocka_run_group_tests(tests, NULL, NULL);
}
