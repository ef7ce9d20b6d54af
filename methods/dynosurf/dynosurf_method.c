/* dynosurf: DynoSurf (ECCV 2024): an implicit template — an SDF on a
 * tetrahedral grid around the keyframe's convex hull, extracted by
 * marching tetrahedra (methods/dynosurf/grid.h, template.h) — carried into
 * every frame by 30 learned control points blended with learned weights
 * (methods/dynosurf/deformer.h, motion.h), fitted per sequence in four
 * phases (methods/dynosurf/train.h). docs/protocol.md, "DynoSurf", lists
 * the reference files followed and every difference.
 *
 * Params (presets overridable key by key; default cpu):
 *   preset         paper (the reference's iterations and sizes: 1 000 +
 *                  5 000 + 4 000 + 10 000 steps, 5 000 points a frame,
 *                  10 000 samples, tets of 4.5e-7), cpu (sizes for one
 *                  core: docs/protocol.md, "DynoSurf"), tiny (tests)
 *   normals        input (default: the normals the sequence's input comes
 *                  with, estimated when it comes with none) | estimated |
 *                  gt (the reference reads each frame's normals from its
 *                  files: the ground truth's)
 *   pretrain_steps, template_steps, blend_steps, motion_steps, points,
 *   samples, grid_samples, tet_volume, remesh (the shell's edge, a
 *   fraction of its box diagonal), lr, recon_points, checkpoint_every,
 *   divergence
 *
 * Frame: frame 0's mean and box diagonal (the reference's), which the
 * read-out maps back. The keyframe is the frame of least Chamfer to the
 * others. The grid is rebuilt by fit and load from the drawn clouds (the
 * same seed, the same grid). Read-out, checkpoints and the model file are
 * the pcgrid methods' shared ops (methods/pcgrid/method.h) with the
 * trainer's own template. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "methods/builtin.h"
#include "methods/dynosurf/grid.h"
#include "methods/dynosurf/train.h"
#include "methods/params.h"
#include "methods/pcgrid/method.h"
#include "methods/step_cost.h"
#include "neural/approx_sdf.h"
#include "tcb/json.h"
#include "tcb/meshing.h"

typedef struct dyno_preset {
    long long steps[DYNO_PHASES];
    int points, samples, grid_samples;
    double tet_volume, remesh, lr;
} dyno_preset;

static const dyno_preset presets[] = {
    {{1000, 5000, 4000, 10000}, 5000, 10000, 10000, DYNO_TET_VOLUME, DYNO_REMESH_FRACTION, 1e-4}, /* paper */
    {{1000, 1500, 1000, 800}, 2500, 3000, 1500, 4e-6, 0.02, 1e-4},                                 /* cpu */
    {{100, 30, 10, 15}, 300, 400, 300, 2e-4, 0.05, 1e-3},                                          /* tiny */
};
static const char *const preset_names[] = {"paper", "cpu", "tiny", NULL};

typedef struct dynosurf_method {
    tcb_pcgrid_method base; /* first: the shared ops take the object as it */
    dyno_schedule sched;
    double tet_volume, remesh;
} dynosurf_method;

static const tcb_pcgrid_hooks hooks;

static int parse(const char *params_json, void *obj, tcb_error *err)
{
    dynosurf_method *m = obj;
    tcb_pcgrid_method *b = &m->base;
    static const char *const keys[] = {"preset", "normals", "points", "pretrain_steps", "template_steps",
                                       "blend_steps", "motion_steps", "samples", "grid_samples", "tet_volume",
                                       "remesh", "lr", "recon_points", "checkpoint_every", "divergence", NULL};
    static const char *const step_keys[DYNO_PHASES] = {"pretrain_steps", "template_steps", "blend_steps",
                                                       "motion_steps"};
    const char *where = "dynosurf.params";
    cJSON *j;
    int rc = tcb_params_parse(params_json, where, keys, &j, err);
    if (rc) return rc;
    int pi = 1;
    long long points = 0, samples = 0, grid_samples = 0;
    rc = tcb_json_enum(j, "preset", where, 0, 1, preset_names, &pi, err);
    if (!rc) rc = tcb_pcgrid_parse_common(j, where, b, err);
    const dyno_preset *p = &presets[pi];
    dyno_schedule *s = &m->sched;
    *s = DYNO_SCHEDULE_PAPER;
    for (int k = 0; k < DYNO_PHASES && !rc; k++)
        rc = tcb_json_int(j, step_keys[k], where, 0, p->steps[k], 0, 100000000, &s->steps[k], err);
    if (!rc) rc = tcb_json_int(j, "points", where, 0, p->points, TCB_APPROX_SDF_K, 10000000, &points, err);
    if (!rc) rc = tcb_json_int(j, "samples", where, 0, p->samples, 1, 10000000, &samples, err);
    if (!rc) rc = tcb_json_int(j, "grid_samples", where, 0, p->grid_samples, 1, 10000000, &grid_samples, err);
    if (!rc) rc = tcb_json_num(j, "tet_volume", where, 0, p->tet_volume, 1e-12, 1.0, &m->tet_volume, err);
    if (!rc) rc = tcb_json_num(j, "remesh", where, 0, p->remesh, 1e-4, 0.5, &m->remesh, err);
    if (!rc) rc = tcb_json_num(j, "lr", where, 0, p->lr, 1e-12, 1.0, &s->lr, err);
    if (!rc) rc = tcb_json_num(j, "divergence", where, 0, 1e4, 0, 1e300, &s->divergence, err);
    cJSON_Delete(j);
    if (rc) return rc;
    if (dyno_total_steps(s) < 1) return tcb_fail(err, TCB_ERR_INPUT, "%s: no steps to take", where);
    s->samples = (int)samples, s->grid_samples = (int)grid_samples;
    b->hooks = &hooks, b->fitted.method = hooks.name;
    b->epochs = dyno_total_steps(s), b->points = (int)points;
    return TCB_OK;
}

static int create(const char *params_json, void **self, tcb_error *err)
{
    return tcb_method_create(sizeof(dynosurf_method), "dynosurf", params_json, parse, NULL, self, err);
}

/* ---- the problem: normals, grid and pretraining target over the inputs ---- */

typedef struct problem {
    dyno_problem p;
    float **normals; /* [T] → [n[t]][3] */
    int T;
    tcb_mesh hull, shell;
    tcb_tetmesh grid;
    float *hull_sd;
} problem;

static void problem_free(void *problem_)
{
    problem *pb = problem_;
    for (int t = 0; pb->normals && t < pb->T; t++) free(pb->normals[t]);
    free(pb->normals), free(pb->hull_sd);
    tcb_mesh_free(&pb->hull), tcb_mesh_free(&pb->shell), tcb_tetmesh_free(&pb->grid);
}

static int frame_normals(const tcb_pcgrid_method *b, const tcb_sequence *seq, const tcb_pcgrid_inputs *in,
                         problem *pb, tcb_error *err)
{
    const tcb_pcgrid_clouds *c = &in->clouds;
    int gt = tcb_pcgrid_uses_gt_normals(b, seq);
    pb->T = c->T;
    if (!(pb->normals = calloc((size_t)c->T, sizeof *pb->normals)))
        return tcb_fail(err, TCB_ERR_NOMEM, "out of memory");
    for (int t = 0; t < c->T; t++) {
        if (!(pb->normals[t] = malloc((size_t)c->n[t] * 3 * sizeof(float))))
            return tcb_fail(err, TCB_ERR_NOMEM, "out of memory");
        int rc = gt ? tcb_pcgrid_gt_normals(seq, t, in->map, c->clouds[t], c->n[t], pb->normals[t], err)
                    : tcb_estimate_normals(c->clouds[t], c->n[t], TCB_NORMALS_K, pb->normals[t], err);
        if (rc) return rc;
    }
    return TCB_OK;
}

static int problem_init(void *self, const tcb_sequence *seq, tcb_pcgrid_inputs *in, tcb_error *err)
{
    const dynosurf_method *m = self;
    problem *pb = in->problem;
    const tcb_pcgrid_clouds *c = &in->clouds;
    int rc = frame_normals(&m->base, seq, in, pb, err);
    if (!rc)
        rc = dyno_grid_build(c->clouds[in->key], c->n[in->key], m->tet_volume, m->remesh, &pb->hull, &pb->shell,
                             &pb->grid, err);
    if (!rc && !(pb->hull_sd = malloc((size_t)pb->grid.n_verts * sizeof *pb->hull_sd)))
        rc = tcb_fail(err, TCB_ERR_NOMEM, "out of memory");
    if (!rc) rc = tcb_convex_signed_distance(&pb->hull, pb->grid.verts, pb->grid.n_verts, pb->hull_sd, err);
    if (!rc)
        pb->p = (dyno_problem){c->T, in->key, (const float *const *)c->clouds, (const float *const *)pb->normals,
                               c->n, (const tcb_nn *const *)c->index, &pb->grid,
                               (float)dyno_tet_edge_bound(&pb->grid), pb->hull_sd};
    return rc;
}

static void describe(const void *problem_, char *line, size_t size)
{
    const problem *pb = problem_;
    snprintf(line, size, "keyframe %d; grid %d vertices, %d tets, edge bound %.3g; hull %d faces", pb->p.key,
             pb->grid.n_verts, pb->grid.n_tets, pb->p.edge, pb->hull.n_faces);
}

/* ---- the trainer's hooks (methods/pcgrid/method.h) ---- */

static int trainer_init(void *t, const void *self, const void *pb, uint64_t seed, tcb_error *err)
{
    const dynosurf_method *m = self;
    return dyno_trainer_init(t, &((const problem *)pb)->p, &m->sched, seed, err);
}

static void trainer_free(void *t) { dyno_trainer_free(t); }
static int step(void *t, double *loss, tcb_error *err) { return dyno_train_step(t, loss, err); }
static long long done(const void *t) { return ((const dyno_trainer *)t)->it; }

static int save(const void *t, uint64_t seed, double seconds, const char *path, tcb_error *err)
{
    return dyno_train_save(t, seed, seconds, path, err);
}

static int load(void *t, uint64_t seed, const char *path, double *seconds, tcb_error *err)
{
    return dyno_train_load(t, seed, path, seconds, err);
}

static float *params(void *t_, size_t *n)
{
    dyno_trainer *t = t_;
    *n = t->n_params;
    return t->params;
}

static int frames(void *t, float *X, tcb_error *err) { return dyno_trainer_frames(t, X, err); }

/* The extracted template as a plain mesh for the read-out. */
static int trained_template(void *t, tcb_mesh *out, tcb_error *err)
{
    const tcb_mt_surface *s;
    int rc = dyno_trainer_template(t, &s, err);
    if (rc) return rc;
    *out = (tcb_mesh){s->n_verts, s->n_faces, malloc((size_t)s->n_verts * 3 * sizeof(float)),
                      malloc((size_t)s->n_faces * 3 * sizeof(int32_t))};
    if (!out->verts || !out->faces) {
        tcb_mesh_free(out);
        return tcb_fail(err, TCB_ERR_NOMEM, "dynosurf: out of memory for the template");
    }
    memcpy(out->verts, s->verts, (size_t)s->n_verts * 3 * sizeof(float));
    memcpy(out->faces, s->faces, (size_t)s->n_faces * 3 * sizeof(int32_t));
    return TCB_OK;
}

static cJSON *manifest(const void *self, size_t n_params)
{
    const dynosurf_method *m = self;
    cJSON *j = cJSON_CreateObject();
    cJSON_AddStringToObject(j, "method", "dynosurf");
    cJSON_AddNumberToObject(j, "points", m->base.points);
    cJSON_AddNumberToObject(j, "tet_volume", m->tet_volume);
    cJSON_AddNumberToObject(j, "remesh", m->remesh);
    cJSON_AddNumberToObject(j, "parameters", (double)n_params);
    return j;
}

static void main_phase(void *trainer) { dyno_trainer_main_phase(trainer); }

/* The units tcbench calibrate times besides stage 2's step: the grid (the
 * inputs and problem a fit builds first), a step of each phase before
 * stage 2, named as the phases (unit 1 + p is phase p's step), and what
 * each frame adds to a stage-2 step. */
enum { UNIT_GRID, UNIT_PRETRAIN, UNIT_TEMPLATE, UNIT_BLEND, UNIT_FRAME, N_UNITS };
static const char *const units[] = {"grid", "pretrain", "template", "blend", "frame", NULL};
_Static_assert(sizeof units / sizeof *units - 1 == N_UNITS, "a name per unit");
_Static_assert(N_UNITS <= TCB_MAX_UNIT_USES, "the estimate counts every unit");
_Static_assert(UNIT_BLEND - UNIT_PRETRAIN == DYNO_PHASE_BLEND - DYNO_PHASE_PRETRAIN, "a unit per phase before stage 2");

static int run_unit(void *trainer, int unit, tcb_error *err)
{
    return unit == UNIT_FRAME ? dyno_trainer_frame_unit(trainer, err)
                              : dyno_trainer_unit_step(trainer, unit - UNIT_PRETRAIN + DYNO_PHASE_PRETRAIN, err);
}

static const tcb_pcgrid_hooks hooks = {
    .name = "dynosurf", .magic = "TCBDYNM1",
    .problem_size = sizeof(problem), .trainer_size = sizeof(dyno_trainer),
    .problem_init = problem_init, .problem_free = problem_free,
    .trainer_init = trainer_init, .trainer_free = trainer_free,
    .step = step, .done = done, .save = save, .load = load,
    .params = params, .frames = frames, .manifest = manifest,
    .frame_map = dyno_frame_map, .keyframe = dyno_keyframe, .trained_template = trained_template,
    .describe = describe, .main_phase = main_phase, .run_unit = run_unit,
};

/* ---- the dry run's estimate ---- */

/* The calibrated preset of m's sizes (its steps are counted, not
 * measured); -1 when they differ from each. */
static int calibrated_preset(const dynosurf_method *m)
{
    for (int k = 0; preset_names[k]; k++) {
        const dyno_preset *p = &presets[k];
        if (m->base.points == p->points && m->sched.samples == p->samples &&
            m->sched.grid_samples == p->grid_samples && m->tet_volume == p->tet_volume && m->remesh == p->remesh &&
            m->base.recon_points == TCB_PCGRID_RECON_POINTS)
            return k;
    }
    return -1;
}

/* Stage 2's steps priced by train_steps' step (dyno_trainer_main_phase)
 * plus, for each, its frames' terms by the `frame` unit; the grid and
 * the other phases' steps by their units. train_steps' step is mostly the
 * blend network over the template's vertices and the grid's picks, which
 * the frames do not change; the terms of the calibration sequence's 6
 * frames in it are counted again by the frame units (about 5 % of a step
 * at `paper`, docs/protocol.md). The frames of a step run side by side,
 * one a thread: the frame unit is priced at one thread, its count over
 * the cell's threads. The sequence's vertices scale nothing: the grid's
 * size follows from the hull's volume in the normalised frame. */
static void estimate(void *self, const tcb_cost_query *q, tcb_cost_estimate *out)
{
    const dynosurf_method *m = self;
    const long long *steps = m->sched.steps;
    int k = calibrated_preset(m);
    tcb_step_cost_estimate(hooks.name, preset_names, k, steps[DYNO_PHASE_MOTION], out);
    if (k < 0) return;
    if (q->n_frames < 1) {
        *out = (tcb_cost_estimate){.fit_s = -1, .eval_s = -1};
        snprintf(out->basis, sizeof out->basis, "grows with the frame count (data absent)");
        return;
    }
    int threads = q->n_threads > 1 ? q->n_threads : 1;
    const double count[N_UNITS] = {
        [UNIT_GRID] = 1,
        [UNIT_PRETRAIN] = (double)steps[DYNO_PHASE_PRETRAIN],
        [UNIT_TEMPLATE] = (double)steps[DYNO_PHASE_TEMPLATE],
        [UNIT_BLEND] = (double)steps[DYNO_PHASE_BLEND],
        [UNIT_FRAME] = (double)steps[DYNO_PHASE_MOTION] * q->n_frames / threads,
    };
    for (int u = 0; u < N_UNITS; u++) {
        tcb_unit_use *use = &out->units[out->n_units++];
        *use = (tcb_unit_use){.fit = count[u], .threads = u == UNIT_FRAME ? 1 : 0 /* 0: the cell's */};
        snprintf(use->unit, sizeof use->unit, "%s", units[u]);
    }
}

const tcb_method_ops tcb_method_dynosurf = {
    .abi_version = TCB_METHOD_ABI_VERSION,
    .name = "dynosurf",
    .description = "DynoSurf (ECCV 2024): an SDF on a tetrahedral grid around the keyframe's hull, extracted by "
                   "marching tetrahedra and carried by 30 learned control points; barycentric read-out",
    .create = create,
    .estimate = estimate,
    .presets = preset_names,
    .fit = tcb_pcgrid_fit,
    .transfer = tcb_pcgrid_transfer_op,
    .reconstruct = tcb_pcgrid_reconstruct_op,
    .save = tcb_pcgrid_save,
    .load = tcb_pcgrid_load,
    .destroy = tcb_pcgrid_destroy,
    .surface = tcb_pcgrid_surface_op,
    .train_steps = tcb_pcgrid_train_steps,
    .units = units,
    .run_unit = tcb_pcgrid_run_unit,
    .normals = tcb_pcgrid_normals_used,
};
