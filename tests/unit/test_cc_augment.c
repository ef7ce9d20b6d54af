/* CC per-frame boxes and training augmentation (methods/cycle/augment.h):
 * the box lands a frame in [−1, 1] with largest half-extent 1, apply and
 * invert are inverse, degenerate frames are refused by name; the
 * augmentation's rotation, scaling, renormalization and translation against
 * a double-precision recomputation from its recorded draws and against the
 * raw stream; the self-reconstruction target P4 against a hand computation. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "methods/cycle/augment.h"
#include "tcb/rng.h"
#include "tcb/sequence.h"
#include "testutil.h"

#define PI 3.14159265358979323846
#define DEG (PI / 180.0)

/* n points in an off-centre anisotropic box: centre (3, −2, 5), half-extents
 * (0.5, 2, 1), so the y extent sets the scale. */
static void random_cloud(tcb_rng *r, int n, float *p)
{
    for (int i = 0; i < n; i++) {
        p[3 * i + 0] = (float)(3.0 + 0.5 * (2 * tcb_rng_uniform(r) - 1));
        p[3 * i + 1] = (float)(-2.0 + 2.0 * (2 * tcb_rng_uniform(r) - 1));
        p[3 * i + 2] = (float)(5.0 + 1.0 * (2 * tcb_rng_uniform(r) - 1));
    }
}

static void bbox(const float *p, int n, double c[3], double half[3])
{
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int i = 0; i < n; i++)
        for (int d = 0; d < 3; d++) lo[d] = fmin(lo[d], p[3 * i + d]), hi[d] = fmax(hi[d], p[3 * i + d]);
    for (int d = 0; d < 3; d++) c[d] = 0.5 * (lo[d] + hi[d]), half[d] = 0.5 * (hi[d] - lo[d]);
}

static double max3(const double v[3]) { return fmax(v[0], fmax(v[1], v[2])); }

static void make_seq(tcb_sequence *s, const char *name, int n_frames, int pool_size)
{
    tcb_error err = {0};
    if (tcb_sequence_alloc(s, name, n_frames, 1, 1, &err)) fail_msg("alloc: %s", err.msg);
    memset(s->verts, 0, 3 * sizeof(float) * (size_t)n_frames);
    memset(s->faces, 0, 3 * sizeof(int32_t));
    s->pool_size = pool_size;
    s->pools = malloc(sizeof(float) * 3 * (size_t)n_frames * (size_t)pool_size);
    assert_non_null(s->pools);
}

/* ---- frame boxes ---------------------------------------------------------- */

static void test_frame_box(void **state)
{
    (void)state;
    enum { F = 3, POOL = 500 };
    tcb_sequence s;
    make_seq(&s, "cat_walk", F, POOL);
    tcb_rng r;
    tcb_rng_seed(&r, 3);
    for (int f = 0; f < F; f++) random_cloud(&r, POOL, s.pools + (size_t)f * POOL * 3);
    for (int f = 0; f < F; f++) {
        tcb_cc_frame_box box;
        tcb_error err = {0};
        assert_int_equal(tcb_cc_frame_box_compute(&s, f, &box, &err), TCB_OK);
        const float *p = tcb_seq_pool(&s, f);
        double c[3], half[3];
        bbox(p, POOL, c, half);
        for (int d = 0; d < 3; d++) assert_near(box.center[d], c[d], 1e-6);
        assert_near(box.scale, half[1], 1e-6);
        assert_true(box.scale == (float)max3(half)); /* computed in double, one rounding */

        float q[POOL * 3], back[POOL * 3];
        tcb_cc_frame_box_apply(&box, p, POOL, q);
        for (int i = 0; i < 3 * POOL; i++) assert_true(fabsf(q[i]) <= 1.0f + 1e-6f);
        bbox(q, POOL, c, half);
        for (int d = 0; d < 3; d++) assert_near(c[d], 0.0, 1e-6);
        assert_near(max3(half), 1.0, 1e-6);
        assert_near(half[1], 1.0, 1e-6);
        assert_near(half[0], 0.25, 1e-3); /* x: 0.5 / 2 (the cloud's own extent) */

        /* invert ∘ apply and apply ∘ invert are the identity */
        tcb_cc_frame_box_invert(&box, q, POOL, back);
        for (int i = 0; i < 3 * POOL; i++) assert_near(back[i], p[i], 1e-6);
        tcb_cc_frame_box_invert(&box, q, POOL, back);
        tcb_cc_frame_box_apply(&box, back, POOL, back); /* in place */
        for (int i = 0; i < 3 * POOL; i++) assert_near(back[i], q[i], 1e-6);
    }
    tcb_sequence_free(&s);
}

static void expect_error(int rc, const tcb_error *err, int code, const char *a, const char *b)
{
    assert_int_equal(rc, code);
    if (a && !strstr(err->msg, a)) fail_msg("'%s' does not name '%s'", err->msg, a);
    if (b && !strstr(err->msg, b)) fail_msg("'%s' does not name '%s'", err->msg, b);
}

static void test_frame_box_rejects(void **state)
{
    (void)state;
    enum { F = 4, POOL = 20 };
    tcb_sequence s;
    make_seq(&s, "horse_gallop", F, POOL);
    tcb_rng r;
    tcb_rng_seed(&r, 1);
    for (int f = 0; f < F; f++) random_cloud(&r, POOL, s.pools + (size_t)f * POOL * 3);
    /* frame 1 collapses to a point, frame 2 has a NaN, frame 3 is flat (fine) */
    for (int i = 0; i < POOL; i++) memcpy(s.pools + (1 * POOL + i) * 3, s.pools + POOL * 3, 3 * sizeof(float));
    s.pools[(2 * POOL + 7) * 3 + 1] = NAN;
    for (int i = 0; i < POOL; i++) s.pools[(3 * POOL + i) * 3 + 2] = 1.5f;
    tcb_cc_frame_box box;
    tcb_error err = {0};
    expect_error(tcb_cc_frame_box_compute(&s, 1, &box, &err), &err, TCB_ERR_INPUT, "frame 1",
                 "horse_gallop");
    expect_error(tcb_cc_frame_box_compute(&s, 2, &box, &err), &err, TCB_ERR_INPUT, "frame 2",
                 "horse_gallop");
    expect_error(tcb_cc_frame_box_compute(&s, 4, &box, &err), &err, TCB_ERR_INPUT, "frame 4",
                 "horse_gallop");
    expect_error(tcb_cc_frame_box_compute(&s, -1, &box, &err), &err, TCB_ERR_INPUT, "frame -1",
                 "horse_gallop");
    assert_int_equal(tcb_cc_frame_box_compute(&s, 3, &box, &err), TCB_OK);
    assert_near(box.center[2], 1.5, 0.0);
    /* a cloud of one point, and an infinite one */
    float one[3] = {1, 2, 3}, inf[6] = {0, 0, 0, INFINITY, 1, 1};
    expect_error(tcb_cc_box_of_points(one, 1, "probe", &box, &err), &err, TCB_ERR_INPUT, "probe", NULL);
    expect_error(tcb_cc_box_of_points(inf, 2, "probe", &box, &err), &err, TCB_ERR_INPUT, "probe", NULL);
    /* no pools */
    free(s.pools);
    s.pools = NULL, s.pool_size = 0;
    expect_error(tcb_cc_frame_box_compute(&s, 0, &box, &err), &err, TCB_ERR_INPUT, "horse_gallop", "pool");
    tcb_sequence_free(&s);
}

/* ---- rotation --------------------------------------------------------------- */

static void check_rotation(const float rot[9], double max_angle)
{
    /* orthonormal: rot rotᵀ = I */
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            double dot = 0;
            for (int k = 0; k < 3; k++) dot += (double)rot[3 * i + k] * rot[3 * j + k];
            assert_near(dot, i == j ? 1.0 : 0.0, 1e-6);
        }
    double det = rot[0] * ((double)rot[4] * rot[8] - (double)rot[5] * rot[7]) -
                 rot[1] * ((double)rot[3] * rot[8] - (double)rot[5] * rot[6]) +
                 rot[2] * ((double)rot[3] * rot[7] - (double)rot[4] * rot[6]);
    assert_near(det, 1.0, 1e-6);
    /* about y: the y axis is fixed */
    assert_near(rot[4], 1.0, 0.0);
    assert_near(rot[1], 0.0, 0.0);
    assert_near(rot[3], 0.0, 0.0);
    assert_near(rot[5], 0.0, 0.0);
    assert_near(rot[7], 0.0, 0.0);
    double angle = atan2(rot[6], rot[0]); /* rot = R_y(θ)ᵀ: rot[2][0] = sin θ */
    if (fabs(angle) > max_angle + 1e-6) fail_msg("rotation by %g degrees", angle / DEG);
}

static void test_rot_matrix(void **state)
{
    (void)state;
    const double th = 0.3, c = cos(th), s = sin(th);
    float rot[9];
    tcb_cc_rot_matrix(th, rot);
    /* transpose of get_3D_rot_matrix(1, θ) = [[c, 0, s], [0, 1, 0], [−s, 0, c]] */
    const double expect[9] = {c, 0, -s, 0, 1, 0, s, 0, c};
    for (int i = 0; i < 9; i++) assert_near(rot[i], expect[i], 1e-7);
    check_rotation(rot, th);
    /* a row vector p · rot = R_y(θ) p: x' = c x + s z, z' = −s x + c z */
    const float p[3] = {1.0f, 2.0f, 3.0f};
    double q[3] = {0, 0, 0};
    for (int j = 0; j < 3; j++)
        for (int k = 0; k < 3; k++) q[j] += p[k] * (double)rot[3 * k + j];
    assert_near(q[0], c * 1 + s * 3, 1e-6);
    assert_near(q[1], 2.0, 1e-6);
    assert_near(q[2], -s * 1 + c * 3, 1e-6);
}

/* ---- augmentation ------------------------------------------------------------ */

/* The augmentation recomputed in double from the recorded draws. */
static void ref_augment(const float *in, int n, const tcb_cc_aug *a, double *out)
{
    const double c = cos(a->theta), s = sin(a->theta);
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int i = 0; i < n; i++) {
        const float *p = in + 3 * i;
        double q[3] = {c * p[0] + s * p[2], p[1], -s * p[0] + c * p[2]};
        for (int d = 0; d < 3; d++) {
            q[d] *= a->scale[d];
            out[3 * i + d] = q[d];
            lo[d] = fmin(lo[d], q[d]), hi[d] = fmax(hi[d], q[d]);
        }
    }
    double half = 0.0;
    for (int d = 0; d < 3; d++) half = fmax(half, 0.5 * (hi[d] - lo[d]));
    for (int i = 0; i < n; i++)
        for (int d = 0; d < 3; d++)
            out[3 * i + d] = (out[3 * i + d] - 0.5 * (lo[d] + hi[d])) / half + a->shift[d];
}

static void test_augment(void **state)
{
    (void)state;
    enum { N = 400, T = 300 };
    tcb_rng data, r;
    tcb_rng_seed(&data, 17);
    tcb_rng_seed(&r, 2024);
    float raw[N * 3], in[N * 3], out[N * 3];
    double ref[N * 3];
    double th_lo = 1, th_hi = -1;
    for (int t = 0; t < T; t++) {
        random_cloud(&data, N, raw);
        tcb_cc_frame_box box;
        tcb_error err = {0};
        assert_int_equal(tcb_cc_box_of_points(raw, N, "cloud", &box, &err), TCB_OK);
        tcb_cc_frame_box_apply(&box, raw, N, in);
        memcpy(out, in, sizeof in);

        /* the stream: θ, 3 scales, 3 translations, nothing else */
        tcb_rng copy = r;
        double u[7];
        for (int k = 0; k < 7; k++) u[k] = tcb_rng_uniform(&copy);

        tcb_cc_aug a;
        assert_int_equal(tcb_cc_augment(out, N, &r, &a, &err), TCB_OK);
        assert_memory_equal(&r, &copy, sizeof r);
        assert_near(a.theta, (2 * u[0] - 1) * PI / 9, 1e-12);
        for (int d = 0; d < 3; d++) {
            assert_near(a.scale[d], 0.75 + 0.5 * u[1 + d], 1e-7);
            assert_near(a.shift[d], 0.03 * (2 * u[4 + d] - 1), 1e-9);
            assert_true(a.scale[d] >= 0.75f && a.scale[d] <= 1.25f);
            assert_true(fabsf(a.shift[d]) <= 0.03f);
        }
        th_lo = fmin(th_lo, a.theta), th_hi = fmax(th_hi, a.theta);
        check_rotation(a.rot, 20 * DEG);
        float rot[9];
        tcb_cc_rot_matrix(a.theta, rot);
        assert_memory_equal(rot, a.rot, sizeof rot);

        /* the result: bbox centred at the translation (within 0.03 of 0),
         * largest half-extent 1, different from the input */
        double c[3], half[3];
        bbox(out, N, c, half);
        for (int d = 0; d < 3; d++) {
            assert_near(c[d], a.shift[d], 1e-6);
            assert_true(fabs(c[d]) <= 0.03 + 1e-6);
        }
        assert_near(max3(half), 1.0, 1e-6);
        double diff = 0;
        for (int i = 0; i < 3 * N; i++) diff = fmax(diff, fabs(out[i] - in[i]));
        if (!(diff > 1e-3)) fail_msg("augmentation moved no point by more than %g", diff);

        /* and point by point what the CC code computes */
        ref_augment(in, N, &a, ref);
        for (int i = 0; i < 3 * N; i++) assert_near(out[i], ref[i], 2e-6);
    }
    /* θ covers ±20° */
    if (th_lo > -19 * DEG || th_hi < 19 * DEG)
        fail_msg("theta in [%g, %g] degrees", th_lo / DEG, th_hi / DEG);

    /* NULL aug is allowed; a degenerate cloud is refused */
    float pt[6] = {0.1f, 0.2f, 0.3f, 0.1f, 0.2f, 0.3f};
    tcb_error err = {0};
    expect_error(tcb_cc_augment(pt, 2, &r, NULL, &err), &err, TCB_ERR_INPUT, "augmented", NULL);
    random_cloud(&data, N, out);
    assert_int_equal(tcb_cc_augment(out, N, &r, NULL, &err), TCB_OK);
}

/* The same seed gives the same augmentation. */
static void test_augment_reproducible(void **state)
{
    (void)state;
    enum { N = 50 };
    tcb_rng data, r1, r2;
    tcb_rng_seed(&data, 5);
    float a[N * 3], b[N * 3];
    random_cloud(&data, N, a);
    memcpy(b, a, sizeof a);
    tcb_rng_seed(&r1, 9), tcb_rng_seed(&r2, 9);
    tcb_cc_aug x, y;
    tcb_error err = {0};
    assert_int_equal(tcb_cc_augment(a, N, &r1, &x, &err), TCB_OK);
    assert_int_equal(tcb_cc_augment(b, N, &r2, &y, &err), TCB_OK);
    assert_memory_equal(a, b, sizeof a);
    assert_memory_equal(&x, &y, sizeof x);
}

/* ---- self-reconstruction target ------------------------------------------------ */

static void test_selfrec_target(void **state)
{
    (void)state;
    const double th = 0.2, c = cos(th), sn = sin(th);
    float rot[9];
    tcb_cc_rot_matrix(th, rot);
    const float s[3] = {0.1f, -0.3f, 0.4f};
    const float p3[2 * 3] = {1.0f, 2.0f, 3.0f, -0.5f, 0.25f, 0.75f};
    float p4[2 * 3];
    tcb_cc_selfrec_target(p3, 2, rot, s, p4);
    /* By hand: rotᵀ = R_y(θ), P3 · R_y(θ) for a row (x, y, z) is
     * (c x − s z, y, s x + c z); then ⊙ (1 + s). */
    for (int i = 0; i < 2; i++) {
        const float *p = p3 + 3 * i;
        double q[3] = {c * p[0] - sn * p[2], p[1], sn * p[0] + c * p[2]};
        for (int d = 0; d < 3; d++) assert_near(p4[3 * i + d], q[d] * (1.0 + s[d]), 1e-6);
    }
    /* first point, numerically: (c − 3s, 2, s + 3c) ⊙ (1.1, 0.7, 1.4) */
    assert_near(p4[0], (c - 3 * sn) * 1.1, 1e-6);
    assert_near(p4[1], 2.0 * 0.7, 1e-6);
    assert_near(p4[2], (sn + 3 * c) * 1.4, 1e-6);

    /* With s = 0, P4 undoes the augmentation's rotation: P3 = P · rot
     * gives P4 = P. */
    enum { N = 64 };
    tcb_rng data;
    tcb_rng_seed(&data, 8);
    float p[N * 3], rotated[N * 3], back[N * 3];
    for (int i = 0; i < 3 * N; i++) p[i] = (float)(2 * tcb_rng_uniform(&data) - 1);
    for (int i = 0; i < N; i++)
        for (int j = 0; j < 3; j++)
            rotated[3 * i + j] = (p[3 * i] * rot[j] + p[3 * i + 1] * rot[3 + j]) + p[3 * i + 2] * rot[6 + j];
    const float zero[3] = {0, 0, 0};
    tcb_cc_selfrec_target(rotated, N, rot, zero, back);
    for (int i = 0; i < 3 * N; i++) assert_near(back[i], p[i], 1e-6);
}

static void test_selfrec_scale(void **state)
{
    (void)state;
    tcb_rng r, copy;
    tcb_rng_seed(&r, 31);
    double lo = 1, hi = -1;
    for (int t = 0; t < 2000; t++) {
        copy = r;
        float s[3];
        tcb_cc_selfrec_draw_scale(&r, s);
        for (int d = 0; d < 3; d++) {
            assert_near(s[d], tcb_rng_uniform(&copy) - 0.5, 1e-7); /* x, y, z in order */
            assert_true(s[d] >= -0.5f && s[d] <= 0.5f);
            lo = fmin(lo, s[d]), hi = fmax(hi, s[d]);
        }
        assert_memory_equal(&r, &copy, sizeof r);
    }
    if (lo > -0.49 || hi < 0.49) fail_msg("s in [%g, %g]", lo, hi);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_frame_box),
        cmocka_unit_test(test_frame_box_rejects),
        cmocka_unit_test(test_rot_matrix),
        cmocka_unit_test(test_augment),
        cmocka_unit_test(test_augment_reproducible),
        cmocka_unit_test(test_selfrec_target),
        cmocka_unit_test(test_selfrec_scale),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
