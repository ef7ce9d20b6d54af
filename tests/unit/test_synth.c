/* Embedded synthetic sequences: catalogue, mesh validity (closed, oriented,
 * connected sphere), near-isometric but real motion of the gaits, a
 * strongly non-isometric collapse, mirror symmetry of the rest shape,
 * determinism and input errors. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "datasets/synth_internal.h"
#include "tcb/distortion.h"
#include "tcb/geometry.h"
#include "tcb/synth.h"
#include "testutil.h"

#define MIN_FACE_AREA 1e-7 /* body length ≈ 1; the smallest measured is ~2e-5 */
#define ISOMETRY_TOL  0.02 /* total area and mean edge length vs frame 0 (measured ≤ 0.4 %) */
#define MIN_MOTION    0.05 /* max vertex displacement, frame 0 → K/2 (measured ≥ 0.15) */
#define SYMMETRY_TOL  1e-5 /* mirror image to nearest vertex (measured ~1e-8) */
/* The collapse's last frame against its first (measured at seed 5: edges 31.2 %,
 * geodesics 19.8 %, area 0.709; the gaits stay under 5 %). */
#define COLLAPSE_MIN_EDGE 0.25
#define COLLAPSE_MIN_GEO  0.15
#define COLLAPSE_MAX_AREA 0.8

static const char *const names[] = {"quadruped_walk", "quadruped_trot", "humanoid_jacks",
                                    "quadruped_collapse"};
#define N_NAMES 4

static void generate(const char *name, uint64_t seed, int n_frames, tcb_sequence *s)
{
    tcb_error err = {0};
    int rc = tcb_synth_generate(name, seed, n_frames, s, &err);
    if (rc) fail_msg("%s: %s", name, err.msg);
}

static void test_catalogue(void **state)
{
    (void)state;
    assert_int_equal(tcb_synth_count(), N_NAMES);
    for (int k = 0; k < N_NAMES; k++) {
        assert_string_equal(tcb_synth_name(k), names[k]);
        assert_non_null(tcb_synth_description(k));
        assert_true(strlen(tcb_synth_description(k)) > 10);
    }
    assert_null(tcb_synth_name(N_NAMES));
    assert_null(tcb_synth_name(-1));
    assert_null(tcb_synth_description(N_NAMES));
}

static void test_unknown_name(void **state)
{
    (void)state;
    tcb_sequence s;
    tcb_error err = {0};
    assert_int_equal(tcb_synth_generate("cat_walk", 0, 0, &s, &err), TCB_ERR_INPUT);
    assert_int_equal(err.code, TCB_ERR_INPUT);
    assert_non_null(strstr(err.msg, "cat_walk"));
    assert_non_null(strstr(err.msg, "quadruped_walk"));
    assert_int_equal(tcb_synth_generate(NULL, 0, 0, &s, &err), TCB_ERR_INPUT);
    assert_int_equal(tcb_synth_generate("humanoid_jacks", 0, INT_MAX, &s, &err), TCB_ERR_INPUT);
}

static void test_lengths(void **state)
{
    const char *name = *state;
    tcb_sequence s;
    generate(name, 0, 0, &s);
    assert_true(s.n_frames >= 30);
    assert_string_equal(s.name, name);
    tcb_sequence_free(&s);
    generate(name, 0, 31, &s);
    assert_int_equal(s.n_frames, 31);
    tcb_sequence_free(&s);
}

/* ---- topology ----------------------------------------------------------- */

static int32_t root(int32_t *parent, int32_t v)
{
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
}

static int count_components(const tcb_sequence *s)
{
    int32_t *parent = malloc((size_t)s->n_verts * sizeof *parent);
    assert_non_null(parent);
    for (int v = 0; v < s->n_verts; v++) parent[v] = v;
    for (int f = 0; f < s->n_faces; f++)
        for (int i = 1; i < 3; i++)
            parent[root(parent, s->faces[3 * f + i])] = root(parent, s->faces[3 * f]);
    int n = 0;
    for (int v = 0; v < s->n_verts; v++) n += root(parent, v) == v;
    free(parent);
    return n;
}

static void test_topology(void **state)
{
    tcb_sequence s;
    generate(*state, 0, 0, &s);
    assert_in_range(s.n_verts, 1500, 3000);
    for (int f = 0; f < s.n_faces; f++) {
        const int32_t *t = s.faces + 3 * f;
        for (int i = 0; i < 3; i++) assert_in_range(t[i], 0, s.n_verts - 1);
        assert_true(t[0] != t[1] && t[1] != t[2] && t[2] != t[0]);
    }
    assert_true(tu_closed_oriented(s.faces, s.n_faces));
    assert_int_equal(count_components(&s), 1);
    /* A closed connected surface with V − E + F = 2 is a sphere (E = 3F/2). */
    assert_int_equal(s.n_verts - 3 * s.n_faces / 2 + s.n_faces, 2);
    tcb_sequence_free(&s);
}

/* ---- geometry per frame ------------------------------------------------- */

static double signed_volume(const float *v, const int32_t *faces, int nf)
{
    double vol = 0.0;
    for (int f = 0; f < nf; f++) {
        const float *a = v + 3 * faces[3 * f], *b = v + 3 * faces[3 * f + 1],
                    *c = v + 3 * faces[3 * f + 2];
        vol += a[0] * ((double)b[1] * c[2] - (double)b[2] * c[1]) -
               a[1] * ((double)b[0] * c[2] - (double)b[2] * c[0]) +
               a[2] * ((double)b[0] * c[1] - (double)b[1] * c[0]);
    }
    return vol / 6.0;
}

static double mean_edge(const float *v, const int32_t *faces, int nf)
{
    double sum = 0.0;
    for (int f = 0; f < nf; f++)
        for (int i = 0; i < 3; i++) {
            const float *a = v + 3 * faces[3 * f + i], *b = v + 3 * faces[3 * f + (i + 1) % 3];
            sum +=
                sqrt(((double)a[0] - b[0]) * (a[0] - b[0]) + ((double)a[1] - b[1]) * (a[1] - b[1]) +
                     ((double)a[2] - b[2]) * (a[2] - b[2]));
        }
    return sum / (3.0 * nf);
}

static void test_frames(void **state)
{
    tcb_sequence s;
    generate(*state, 3, 0, &s);
    const float *v0 = tcb_seq_frame(&s, 0);
    double area0 = tcb_mesh_area(v0, s.faces, s.n_faces), edge0 = mean_edge(v0, s.faces, s.n_faces);
    for (int f = 0; f < s.n_frames; f++) {
        const float *v = tcb_seq_frame(&s, f);
        for (int t = 0; t < s.n_faces; t++) {
            const int32_t *q = s.faces + 3 * t;
            assert_true(tcb_triangle_area(v + 3 * q[0], v + 3 * q[1], v + 3 * q[2]) >
                        MIN_FACE_AREA);
        }
        assert_true(signed_volume(v, s.faces, s.n_faces) > 0.0);
        assert_true(fabs(tcb_mesh_area(v, s.faces, s.n_faces) / area0 - 1.0) < ISOMETRY_TOL);
        assert_true(fabs(mean_edge(v, s.faces, s.n_faces) / edge0 - 1.0) < ISOMETRY_TOL);
    }
    const float *vh = tcb_seq_frame(&s, s.n_frames / 2);
    double moved = 0.0;
    for (int i = 0; i < 3 * s.n_verts; i += 3) {
        double d = hypot(hypot(v0[i] - vh[i], v0[i + 1] - vh[i + 1]), v0[i + 2] - vh[i + 2]);
        moved = fmax(moved, d);
    }
    assert_true(moved > MIN_MOTION);
    tcb_sequence_free(&s);
}

/* The collapse: starts as the quadruped at rest, ends far from isometric
 * (docs/datasets.md quotes the figures), gets there steadily, and stays a
 * valid closed mesh on or above the ground. */
static void test_collapse(void **state)
{
    (void)state;
    tcb_sequence s;
    generate("quadruped_collapse", 5, 0, &s);
    tcb_distortion *d = calloc((size_t)s.n_frames, sizeof *d);
    tcb_error err = {0};
    assert_int_equal(tcb_sequence_distortion(&s, d, &err), TCB_OK);
    const tcb_distortion *last = &d[s.n_frames - 1];
    assert_true(d[1].edge_mean < 0.01);
    assert_true(last->edge_mean > COLLAPSE_MIN_EDGE);
    assert_true(last->geo_mean > COLLAPSE_MIN_GEO);
    assert_true(last->area_ratio < COLLAPSE_MAX_AREA);
    for (int f = 1; f < s.n_frames; f++) assert_true(d[f].geo_mean >= d[f - 1].geo_mean);
    for (int f = 0; f < s.n_frames; f++) {
        const float *v = tcb_seq_frame(&s, f);
        assert_true(signed_volume(v, s.faces, s.n_faces) > 0.0);
        for (int i = 0; i < s.n_verts; i++) assert_true(v[3 * i + 1] > 0.0f);
    }
    /* The feet start on the ground and sink into the floor layer. */
    const float *v0 = tcb_seq_frame(&s, 0), *vl = tcb_seq_frame(&s, s.n_frames - 1);
    float top0 = 0.0f, topl = 0.0f;
    for (int i = 0; i < s.n_verts; i++) top0 = fmaxf(top0, v0[3 * i + 1]), topl = fmaxf(topl, vl[3 * i + 1]);
    assert_true(topl < 0.5f * top0);
    free(d);
    tcb_sequence_free(&s);
}

/* Reflecting x → −x maps the rest vertex set onto itself (brute-force
 * nearest neighbour); the shape is not flat, so the test has teeth. */
static void test_rest_symmetry(void **state)
{
    float *v;
    int32_t *faces;
    int nv, nf;
    tcb_error err = {0};
    assert_int_equal(tcb_synth_rest_mesh(*state, &v, &nv, &faces, &nf, &err), TCB_OK);
    double worst = 0.0, width = 0.0;
    for (int i = 0; i < nv; i++) {
        const float *p = v + 3 * i;
        double best = INFINITY;
        for (int j = 0; j < nv; j++) {
            const float *q = v + 3 * j;
            double dx = (double)p[0] + q[0], dy = (double)p[1] - q[1], dz = (double)p[2] - q[2];
            best = fmin(best, dx * dx + dy * dy + dz * dz);
        }
        worst = fmax(worst, sqrt(best));
        width = fmax(width, fabs(p[0]));
    }
    assert_true(width > 0.1);
    assert_true(worst < SYMMETRY_TOL);
    free(v);
    free(faces);
}

static void test_determinism(void **state)
{
    tcb_sequence a, b, c;
    generate(*state, 11, 0, &a);
    generate(*state, 11, 0, &b);
    generate(*state, 12, 0, &c);
    size_t nv = (size_t)a.n_frames * a.n_verts * 3, nf = (size_t)a.n_faces * 3;
    assert_int_equal(b.n_verts, a.n_verts);
    assert_memory_equal(a.verts, b.verts, nv * sizeof *a.verts);
    assert_memory_equal(a.faces, b.faces, nf * sizeof *a.faces);
    /* Another seed changes the motion and proportions, never the topology. */
    assert_int_equal(c.n_verts, a.n_verts);
    assert_int_equal(c.n_faces, a.n_faces);
    assert_memory_equal(a.faces, c.faces, nf * sizeof *a.faces);
    assert_memory_not_equal(a.verts, c.verts, nv * sizeof *a.verts);
    tcb_sequence_free(&a);
    tcb_sequence_free(&b);
    tcb_sequence_free(&c);
}

/* One named cmocka case per sequence, e.g. "test_frames(quadruped_trot)". */
#define ONE(fn, seq) {.name = #fn "(" seq ")", .test_func = fn, .initial_state = (void *)seq}
#define PER_GAIT(fn)                                                                               \
    ONE(fn, "quadruped_walk"), ONE(fn, "quadruped_trot"), ONE(fn, "humanoid_jacks")
#define PER_SEQUENCE(fn) PER_GAIT(fn), ONE(fn, "quadruped_collapse")

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_catalogue), cmocka_unit_test(test_unknown_name),
        PER_SEQUENCE(test_lengths),       PER_SEQUENCE(test_topology),
        PER_GAIT(test_frames),            PER_SEQUENCE(test_rest_symmetry),
        PER_SEQUENCE(test_determinism),   cmocka_unit_test(test_collapse),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
