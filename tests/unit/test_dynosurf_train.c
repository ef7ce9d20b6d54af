/* methods/dynosurf/train.c on three frames of a turning ellipsoid and a
 * coarse grid: the phases follow one another (their boundaries, the
 * optimiser's parameters: the pretraining moves the shape network alone,
 * the blend pretraining MLP_W alone, stage 2 the deformer alone), the
 * pretraining losses fall, the fitted frames are finite and share the
 * template's vertices; a run resumed from a checkpoint in stage 2 (the
 * template extracted again from the loaded weights) ends bit for bit where
 * the unbroken run ends; a checkpoint of another schedule is refused;
 * tcbench calibrate's units and the dry run's estimate that counts them. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "methods/builtin.h"
#include "methods/dynosurf/grid.h"
#include "methods/dynosurf/train.h"
#include "tcb/meshing.h"
#include "tcb/rng.h"

enum { T = 3, N = 600 };

typedef struct fixture {
    float pts[T][3 * N], nrm[T][3 * N];
    const float *pp[T], *np[T];
    int n[T];
    tcb_nn *index[T];
    tcb_mesh hull, grown, shell;
    tcb_tetmesh grid;
    float *sd;
    dyno_problem p;
} fixture;

static fixture *fx;

static int setup(void **state)
{
    (void)state;
    fx = calloc(1, sizeof *fx);
    tcb_rng rng;
    tcb_rng_seed(&rng, 4);
    const double ax[3] = {0.3, 0.2, 0.15};
    for (int t = 0; t < T; t++) {
        double a = 0.2 * t, c = cos(a), s = sin(a);
        for (int i = 0; i < N; i++) {
            double u[3] = {tcb_rng_normal(&rng), tcb_rng_normal(&rng), tcb_rng_normal(&rng)};
            double len = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]), q[3], g[3], gl = 0;
            for (int k = 0; k < 3; k++) q[k] = ax[k] * u[k] / len, g[k] = u[k] / len / ax[k], gl += g[k] * g[k];
            gl = sqrt(gl);
            float *p = fx->pts[t] + 3 * i, *nn = fx->nrm[t] + 3 * i;
            p[0] = (float)(c * q[0] - s * q[1]), p[1] = (float)(s * q[0] + c * q[1]), p[2] = (float)q[2];
            nn[0] = (float)((c * g[0] - s * g[1]) / gl), nn[1] = (float)((s * g[0] + c * g[1]) / gl);
            nn[2] = (float)(g[2] / gl);
        }
        fx->pp[t] = fx->pts[t], fx->np[t] = fx->nrm[t], fx->n[t] = N;
    }
    tcb_error err = {0};
    for (int t = 0; t < T; t++)
        if (tcb_nn_build(fx->pts[t], N, &fx->index[t], &err)) return 1;
    /* a coarse grid: the grown hull remeshed to edges of 0.04 */
    if (tcb_convex_hull(fx->pts[1], N, &fx->hull, &err) ||
        tcb_convex_offset(fx->pts[1], N, DYNO_SHELL_OFFSET, &fx->grown, &err) ||
        tcb_mesh_remesh(&fx->grown, 0.04, DYNO_REMESH_ITERATIONS, &fx->shell, &err) ||
        tcb_tetrahedralize(&fx->shell, 2e-4, DYNO_TET_RADIUS_EDGE, &fx->grid, &err))
        return 1;
    fx->sd = malloc((size_t)fx->grid.n_verts * sizeof *fx->sd);
    if (tcb_convex_signed_distance(&fx->hull, fx->grid.verts, fx->grid.n_verts, fx->sd, &err)) return 1;
    fx->p = (dyno_problem){.T = T, .key = 1, .pts = fx->pp, .normals = fx->np, .n_pts = fx->n,
                           .index = (const tcb_nn *const *)fx->index, .grid = &fx->grid,
                           .edge = (float)dyno_tet_edge_bound(&fx->grid), .hull_sd = fx->sd};
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    for (int t = 0; t < T; t++) tcb_nn_free(fx->index[t]);
    tcb_mesh_free(&fx->hull), tcb_mesh_free(&fx->grown), tcb_mesh_free(&fx->shell), tcb_tetmesh_free(&fx->grid);
    free(fx->sd), free(fx);
    return 0;
}

static dyno_schedule schedule(void)
{
    return (dyno_schedule){{100, 30, 30, 12}, 400, 300, 64, 1e-3, 0};
}

/* Which parameter blocks moved over a step: shape, control + MLP_T, MLP_W. */
static void moved(const dyno_trainer *t, const float *before, int out[3])
{
    size_t blend = t->n_shape + dyno_deformer_blend_offset();
    const size_t b[4] = {0, t->n_shape, blend, t->n_params};
    for (int k = 0; k < 3; k++) out[k] = memcmp(before + b[k], t->params + b[k], (b[k + 1] - b[k]) * sizeof(float)) != 0;
}

/* The unbroken run's checkpoint at iteration cut and its final
 * parameters, for test_resume. */
static char ckpt_path[] = "/tmp/tcb_dyno_ckptXXXXXX";
static float *final_params;

static void test_phases(void **state)
{
    (void)state;
    dyno_schedule s = schedule();
    dyno_trainer t;
    tcb_error err = {0};
    int fd = mkstemp(ckpt_path);
    assert_true(fd >= 0);
    close(fd);
    assert_int_equal(dyno_trainer_init(&t, &fx->p, &s, 7, &err), TCB_OK);
    long long total = dyno_total_steps(&s), start;
    float *before = malloc(t.n_params * sizeof *before);
    double first[DYNO_PHASES] = {0}, loss;
    static const int expect[DYNO_PHASES][3] = {{1, 0, 0}, {1, 0, 0}, {0, 0, 1}, {0, 1, 1}};
    for (long long it = 0; it < total; it++) {
        int phase = dyno_phase_of(&s, it, &start);
        memcpy(before, t.params, t.n_params * sizeof *before);
        assert_int_equal(dyno_train_step(&t, &loss, &err), TCB_OK);
        if (it == start) first[phase] = loss;
        int m[3];
        moved(&t, before, m);
        for (int k = 0; k < 3; k++) assert_int_equal(m[k], expect[phase][k]);
        if (t.it == total - 5) assert_int_equal(dyno_train_save(&t, 7, 1.0, ckpt_path, &err), TCB_OK);
    }
    final_params = malloc(t.n_params * sizeof *final_params);
    memcpy(final_params, t.params, t.n_params * sizeof *final_params);
    assert_true(t.last[DYNO_PHASE_PRETRAIN] < 0.5 * first[DYNO_PHASE_PRETRAIN]);
    assert_true(t.last[DYNO_PHASE_BLEND] < first[DYNO_PHASE_BLEND]);
    const tcb_mt_surface *templ;
    assert_int_equal(dyno_trainer_template(&t, &templ, &err), TCB_OK);
    assert_true(templ->n_faces > 100);
    float *X = malloc((size_t)T * templ->n_verts * 3 * sizeof *X);
    assert_int_equal(dyno_trainer_frames(&t, X, &err), TCB_OK);
    for (size_t i = 0; i < (size_t)T * templ->n_verts * 3; i++) assert_true(isfinite(X[i]));
    free(X), free(before);
    dyno_trainer_free(&t);
}

/* From test_phases' checkpoint in stage 2 to the end: its final weights. */
static void test_resume(void **state)
{
    (void)state;
    assert_non_null(final_params);
    dyno_schedule s = schedule();
    long long total = dyno_total_steps(&s);
    dyno_trainer b;
    tcb_error err = {0};
    double loss, seconds;
    assert_int_equal(dyno_trainer_init(&b, &fx->p, &s, 7, &err), TCB_OK);
    assert_int_equal(dyno_train_step(&b, &loss, &err), TCB_OK); /* a state to be overwritten */
    assert_int_equal(dyno_train_load(&b, 7, ckpt_path, &seconds, &err), TCB_OK);
    assert_int_equal(b.it, total - 5);
    while (b.it < total) assert_int_equal(dyno_train_step(&b, &loss, &err), TCB_OK);
    assert_memory_equal(final_params, b.params, b.n_params * sizeof(float));
    dyno_trainer_free(&b);
    /* another schedule's checkpoint */
    dyno_schedule other = s;
    other.steps[DYNO_PHASE_MOTION]++;
    assert_int_equal(dyno_trainer_init(&b, &fx->p, &other, 7, &err), TCB_OK);
    assert_int_equal(dyno_train_load(&b, 7, ckpt_path, &seconds, &err), TCB_ERR_INPUT);
    assert_non_null(strstr(err.msg, "motion steps"));
    dyno_trainer_free(&b);
    unlink(ckpt_path);
    free(final_params);
}

/* train_steps' calibration: stage 2 from its first step, on the hull's
 * zero set, moving the deformer alone. */
static void test_main_phase(void **state)
{
    (void)state;
    dyno_schedule s = schedule();
    dyno_trainer t;
    tcb_error err = {0};
    double loss;
    assert_int_equal(dyno_trainer_init(&t, &fx->p, &s, 7, &err), TCB_OK);
    dyno_trainer_main_phase(&t);
    long long start;
    assert_int_equal(dyno_phase_of(&s, t.it, &start), DYNO_PHASE_MOTION);
    assert_true(t.it == start);
    float *before = malloc(t.n_params * sizeof *before);
    memcpy(before, t.params, t.n_params * sizeof *before);
    assert_int_equal(dyno_train_step(&t, &loss, &err), TCB_OK);
    assert_true(isfinite(loss) && loss > 0);
    int m[3];
    moved(&t, before, m);
    assert_int_equal(m[0], 0), assert_int_equal(m[1], 1), assert_int_equal(m[2], 1);
    const tcb_mt_surface *templ;
    assert_int_equal(dyno_trainer_template(&t, &templ, &err), TCB_OK);
    assert_true(templ->n_faces > 100);
    /* the hull's zero set on the undeformed grid: each vertex where the
     * hull's signed distance, linear along its grid edge, crosses zero */
    for (int i = 0; i < templ->n_verts; i++) {
        int a = templ->edges[2 * i], b = templ->edges[2 * i + 1];
        double da = fx->sd[a], db = fx->sd[b], w = da / (da - db);
        assert_true(da * db < 0);
        for (int k = 0; k < 3; k++) {
            double pa = fx->grid.verts[3 * a + k], pb = fx->grid.verts[3 * b + k];
            assert_true(fabs(templ->verts[3 * i + k] - (pa + w * (pb - pa))) < 1e-5);
        }
    }
    free(before);
    dyno_trainer_free(&t);
}

/* The units of tcbench calibrate: each steps its own phase's parameters
 * and stays in its phase past the phase's end (over its steps, the
 * optimiser started over); stage 1's, from a trainer in stage 2 that never
 * pretrained, is first given a network whose zero set is a surface of at
 * least 90 % of the hull's faces. */
static void test_unit_steps(void **state)
{
    (void)state;
    dyno_schedule s = schedule();
    dyno_trainer t;
    tcb_error err = {0};
    assert_int_equal(dyno_trainer_init(&t, &fx->p, &s, 7, &err), TCB_OK);
    dyno_trainer_main_phase(&t);
    const int blocks[3][3] = {{1, 0, 0}, {1, 0, 0}, {0, 0, 1}}; /* shape, control + MLP_T, MLP_W */
    float *before = malloc(t.n_params * sizeof *before);
    const int phases[2] = {DYNO_PHASE_TEMPLATE, DYNO_PHASE_PRETRAIN}; /* stage 1's first: never pretrained */
    for (int q = 0; q < 2; q++) {
        int phase = phases[q];
        for (long long k = 0; k < s.steps[phase] + 3; k++) {
            memcpy(before, t.params, t.n_params * sizeof *before);
            assert_int_equal(dyno_trainer_unit_step(&t, phase, &err), TCB_OK);
            long long start;
            assert_int_equal(dyno_phase_of(&s, t.it, &start), phase);
            int m[3];
            moved(&t, before, m);
            for (int b = 0; b < 3; b++) assert_int_equal(m[b], blocks[phase][b]);
        }
        if (phase != DYNO_PHASE_TEMPLATE) continue;
        tcb_mt_surface net = {0}, hull = {0};
        assert_int_equal(dyno_template_extract(&t.tfit, &t.shape, &net, &err), TCB_OK);
        assert_int_equal(dyno_template_extract_target(&t.tfit, fx->sd, &hull, &err), TCB_OK);
        assert_true(net.n_faces >= 0.9 * hull.n_faces);
        tcb_mt_surface_free(&net), tcb_mt_surface_free(&hull);
    }
    memcpy(before, t.params, t.n_params * sizeof *before);
    assert_int_equal(dyno_trainer_unit_step(&t, DYNO_PHASE_BLEND, &err), TCB_OK);
    int m[3];
    moved(&t, before, m);
    for (int b = 0; b < 3; b++) assert_int_equal(m[b], blocks[DYNO_PHASE_BLEND][b]);
    assert_int_equal(dyno_trainer_unit_step(&t, DYNO_PHASE_MOTION, &err), TCB_ERR_INTERNAL);
    free(before);
    dyno_trainer_free(&t);
}

/* The `frame` unit: a fresh trainer first takes a stage-2 step (it needs
 * the step's blend weights and transforms), then each run redoes frame
 * 0's terms on them and moves no parameter: its deformation and
 * approximate SDF, poisoned before, come back to the step's values bit
 * for bit, and its Chamfer's gradient is finite. */
static void test_frame_unit(void **state)
{
    (void)state;
    dyno_schedule s = schedule();
    dyno_trainer t;
    tcb_error err = {0};
    assert_int_equal(dyno_trainer_init(&t, &fx->p, &s, 7, &err), TCB_OK);
    float *before = malloc(t.n_params * sizeof *before);
    memcpy(before, t.params, t.n_params * sizeof *before);
    assert_int_equal(dyno_trainer_frame_unit(&t, &err), TCB_OK);
    int m[3];
    moved(&t, before, m);
    assert_int_equal(m[0], 0), assert_int_equal(m[1], 1), assert_int_equal(m[2], 1); /* the stage-2 step */
    dyno_motion_fit *f = &t.mfit;
    size_t nx = 3 * (size_t)f->data.n_template, ns = (size_t)f->data.n_grid_samples;
    float *X0 = malloc(nx * sizeof *X0), *s0 = malloc(ns * sizeof *s0);
    memcpy(X0, f->X, nx * sizeof *X0), memcpy(s0, f->s, ns * sizeof *s0);
    for (int run = 0; run < 2; run++) {
        for (size_t i = 0; i < nx; i++) f->X[i] = f->dX[i] = NAN;
        for (size_t i = 0; i < ns; i++) f->s[i] = NAN;
        memcpy(before, t.params, t.n_params * sizeof *before);
        assert_int_equal(dyno_trainer_frame_unit(&t, &err), TCB_OK);
        moved(&t, before, m);
        assert_int_equal(m[0] + m[1] + m[2], 0);
        assert_memory_equal(f->X, X0, nx * sizeof *X0);
        assert_memory_equal(f->s, s0, ns * sizeof *s0);
        for (size_t i = 0; i < nx; i++) assert_true(isfinite(f->dX[i]));
    }
    free(X0), free(s0), free(before);
    dyno_trainer_free(&t);
}

/* The dry run's estimate: stage 2's steps by train_steps' step, the grid
 * once, each earlier phase's steps by its unit, and each stage-2 step's
 * frames by the frame unit over the cell's threads; without the frame
 * count, no price. */
static void test_estimate(void **state)
{
    (void)state;
    const tcb_method_ops *ops = &tcb_method_dynosurf;
    void *self = NULL;
    tcb_error err = {0};
    assert_int_equal(ops->create("{\"preset\": \"cpu\"}", &self, &err), TCB_OK);
    const struct { int frames, threads; double frame_units; } cases[] = {{6, 1, 4800}, {175, 1, 140000}, {175, 2, 70000}};
    for (size_t c = 0; c < sizeof cases / sizeof *cases; c++) {
        tcb_cost_query q = {cases[c].frames, 2688, 500, cases[c].threads};
        tcb_cost_estimate e = {0};
        ops->estimate(self, &q, &e);
        assert_string_equal(e.preset, "cpu");
        assert_true(e.steps == 800 && e.step_frames == 0 && e.n_units == 5);
        const char *names[] = {"grid", "pretrain", "template", "blend", "frame"};
        const double fits[] = {1, 1000, 1500, 1000, cases[c].frame_units};
        for (int u = 0; u < 5; u++) {
            assert_string_equal(e.units[u].unit, names[u]);
            assert_true(e.units[u].fit == fits[u] && e.units[u].eval == 0 && e.units[u].exponent == 0);
            assert_int_equal(e.units[u].threads, u == 4);
        }
    }
    tcb_cost_query absent = {0, 0, 500, 1};
    tcb_cost_estimate e = {0};
    ops->estimate(self, &absent, &e);
    assert_true(e.fit_s < 0 && e.eval_s < 0 && e.preset[0] == 0 && e.n_units == 0);
    assert_non_null(strstr(e.basis, "frame count"));
    ops->destroy(self);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_phases),
        cmocka_unit_test(test_resume),
        cmocka_unit_test(test_main_phase),
        cmocka_unit_test(test_unit_steps),
        cmocka_unit_test(test_frame_unit),
        cmocka_unit_test(test_estimate),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
