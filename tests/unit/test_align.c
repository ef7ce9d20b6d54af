/* Rotation alignment (tcb/align.h): known yaws are recovered, the chosen
 * Chamfer is the brute-force minimum over the 120 steps, bad input is
 * refused, and the alignment runs where a loader puts it (before pools). */
#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tcb/align.h"
#include "tcb/sequence.h"
#include "tcb/synth.h"
#include "testutil.h"

#define FRAMES 8
#define SAMPLES 400

/* A synthetic walk, centred per frame, each frame then turned by −k_f
 * steps: aligning it must find k_f (frame 0 keeps its orientation). */
static const int turn[FRAMES] = {0, 7, 37, 80, 119, 60, 3, 100};

static void turned_walk(tcb_sequence *s)
{
    tcb_error err = {0};
    assert_int_equal(tcb_synth_generate("quadruped_walk", 0, FRAMES, s, &err), TCB_OK);
    assert_int_equal(tcb_sequence_normalize(s, TCB_NORM_PER_FRAME, &err), TCB_OK);
    int inverse[FRAMES];
    for (int f = 0; f < FRAMES; f++) inverse[f] = (TCB_ALIGN_STEPS - turn[f]) % TCB_ALIGN_STEPS;
    assert_int_equal(tcb_sequence_apply_yaw(s, inverse, &err), TCB_OK);
    free(s->yaw);
    s->yaw = NULL;
}

/* The turned walk aligned with the subset seed `seed`. */
static void align_turned(tcb_sequence *s, uint64_t seed, int *step, double *cd)
{
    turned_walk(s);
    tcb_error err = {0};
    assert_int_equal(tcb_align_yaw(s, SAMPLES, seed, step, cd, &err), TCB_OK);
}

static void test_recovers_known_turns(void **state)
{
    (void)state;
    tcb_sequence s;
    int step[FRAMES];
    double cd[FRAMES];
    align_turned(&s, 5, step, cd);
    for (int f = 0; f < FRAMES; f++) assert_int_equal(step[f], turn[f]);
    assert_true(cd[0] == 0.0);
    for (int f = 1; f < FRAMES; f++) assert_true(cd[f] > 0.0 && isfinite(cd[f]));
    tcb_sequence_free(&s);
}

static double nearest_d2(const double *p, const double *set, int n)
{
    double best = INFINITY;
    for (int j = 0; j < n; j++) {
        double x = p[0] - set[3 * j], y = p[1] - set[3 * j + 1], z = p[2] - set[3 * j + 2];
        best = fmin(best, x * x + y * y + z * z);
    }
    return best;
}

/* Symmetric Chamfer of R_y(θ)·a to b, in double, by brute force. */
static double brute_chamfer(const float *a, const float *b, int n, double theta)
{
    double c = cos(theta), s = sin(theta), *ra = tu_dalloc(3 * (size_t)n), *db = tu_dalloc(3 * (size_t)n);
    for (int i = 0; i < n; i++) {
        ra[3 * i] = c * a[3 * i] + s * a[3 * i + 2];
        ra[3 * i + 1] = a[3 * i + 1];
        ra[3 * i + 2] = -s * a[3 * i] + c * a[3 * i + 2];
        for (int d = 0; d < 3; d++) db[3 * i + d] = b[3 * i + d];
    }
    double there = 0, back = 0;
    for (int i = 0; i < n; i++) there += nearest_d2(ra + 3 * i, db, n), back += nearest_d2(db + 3 * i, ra, n);
    free(ra), free(db);
    return there / n + back / n;
}

/* The subset tcb_align_yaw measures on, of frame f. */
static void sample_frame(const tcb_sequence *s, int f, uint64_t seed, float *out)
{
    int32_t *ids = malloc((size_t)s->n_verts * sizeof *ids);
    assert_int_equal(tcb_align_vertex_ids(s, SAMPLES, seed, ids), SAMPLES);
    for (int i = 0; i < SAMPLES; i++) memcpy(out + 3 * i, tcb_seq_frame(s, f) + 3 * ids[i], 3 * sizeof(float));
    free(ids);
}

static void rotate(float *p, int n, double theta)
{
    double c = cos(theta), s = sin(theta);
    for (int i = 0; i < n; i++) {
        double x = p[3 * i], z = p[3 * i + 2];
        p[3 * i] = (float)(c * x + s * z), p[3 * i + 2] = (float)(-s * x + c * z);
    }
}

static void test_chamfer_is_the_brute_force_minimum(void **state)
{
    (void)state;
    tcb_sequence s;
    int step[FRAMES];
    double cd[FRAMES];
    align_turned(&s, 9, step, cd);
    float *prev = tu_falloc(3 * SAMPLES), *cur = tu_falloc(3 * SAMPLES);
    sample_frame(&s, 0, 9, prev);
    for (int f = 1; f < 3; f++) {
        sample_frame(&s, f, 9, cur);
        double best = INFINITY;
        int arg = -1;
        for (int k = 0; k < TCB_ALIGN_STEPS; k++) {
            double d = brute_chamfer(cur, prev, SAMPLES, tcb_align_step_radians(k));
            if (d < best) best = d, arg = k;
        }
        assert_int_equal(step[f], arg);
        assert_true(fabs(cd[f] - best) <= 1e-5 * best);
        rotate(cur, SAMPLES, tcb_align_step_radians(step[f]));
        memcpy(prev, cur, 3 * SAMPLES * sizeof(float));
    }
    free(prev), free(cur);
    tcb_sequence_free(&s);
}

/* The loader's order: normalize, align, then pools drawn from the aligned
 * surfaces; yaw recorded. */
static void test_prepare_aligns_before_pools(void **state)
{
    (void)state;
    tcb_sequence s;
    turned_walk(&s);
    tcb_error err = {0};
    tcb_load_opts o = {TCB_NORM_PER_FRAME, 300, 5, NULL, SAMPLES, NULL};
    assert_int_equal(tcb_sequence_prepare(&s, &o, &err), TCB_OK);
    assert_non_null(s.yaw);
    assert_int_equal(s.pool_size, 300);
    for (int f = 0; f < FRAMES; f++) assert_true(fabs(s.yaw[f] - tcb_align_step_radians(turn[f])) < 1e-12);
    /* aligned: every frame now faces as frame 0 does, so its bounding box
     * is close to frame 0's (the turned frames' boxes were not) */
    for (int f = 1; f < FRAMES; f++) {
        double dmax = 0;
        for (int d = 0; d < 3; d += 2) {
            float lo0 = INFINITY, hi0 = -INFINITY, lo = INFINITY, hi = -INFINITY;
            for (int i = 0; i < s.n_verts; i++) {
                float a = tcb_seq_frame(&s, 0)[3 * i + d], b = tcb_seq_frame(&s, f)[3 * i + d];
                lo0 = fminf(lo0, a), hi0 = fmaxf(hi0, a), lo = fminf(lo, b), hi = fmaxf(hi, b);
            }
            dmax = fmax(dmax, fabs((hi - lo) - (hi0 - lo0)) / (hi0 - lo0));
        }
        assert_true(dmax < 0.25);
    }
    assert_int_equal(tcb_sequence_apply_yaw(&s, turn, &err), TCB_ERR_INTERNAL); /* pools exist */
    assert_non_null(strstr(err.msg, "before sampling pools"));
    tcb_sequence_free(&s);
}

static void test_bad_input(void **state)
{
    (void)state;
    tcb_sequence s;
    turned_walk(&s);
    int step[FRAMES] = {0};
    tcb_error err = {0};
    assert_int_equal(tcb_align_yaw(&s, 0, 0, step, NULL, &err), TCB_ERR_INPUT);
    assert_non_null(strstr(err.msg, "alignment samples 0"));
    const float before = tcb_seq_frame(&s, 1)[0];
    step[3] = TCB_ALIGN_STEPS;
    assert_int_equal(tcb_sequence_apply_yaw(&s, step, &err), TCB_ERR_INPUT);
    assert_non_null(strstr(err.msg, "frame 3: yaw step 120"));
    assert_true(tcb_seq_frame(&s, 1)[0] == before); /* nothing rotated */
    assert_null(s.yaw);
    tcb_sequence_free(&s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_recovers_known_turns),
        cmocka_unit_test(test_chamfer_is_the_brute_force_minimum),
        cmocka_unit_test(test_prepare_aligns_before_pools),
        cmocka_unit_test(test_bad_input),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
