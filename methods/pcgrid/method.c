/* The shared ops of a pcgrid method (methods/pcgrid/method.h). */
#include "methods/pcgrid/method.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "methods/step_cost.h"
#include "neural/train_loop.h"
#include "neural/weights.h"

#define CKPT_NAME "train.ckpt"

const char *const tcb_pcgrid_units[] = {"template", NULL};
enum { UNIT_TEMPLATE };

static const char *const normals_names[] = {"estimated", "gt", "input", NULL};

int tcb_pcgrid_parse_common(const cJSON *j, const char *where, tcb_pcgrid_method *b, tcb_error *err)
{
    long long recon;
    int rc = tcb_json_enum(j, "normals", where, 0, TCB_PCGRID_NORMALS_INPUT, normals_names, &b->normals, err);
    if (!rc) rc = tcb_json_int(j, "recon_points", where, 0, TCB_PCGRID_RECON_POINTS, 1, 10000000, &recon, err);
    if (!rc) rc = tcb_json_int(j, "checkpoint_every", where, 0, 50, 0, 100000000, &b->checkpoint_every, err);
    if (!rc) b->recon_points = (int)recon;
    return rc;
}

int tcb_pcgrid_uses_gt_normals(const tcb_pcgrid_method *b, const tcb_sequence *seq)
{
    return b->normals == TCB_PCGRID_NORMALS_GT ||
           (b->normals == TCB_PCGRID_NORMALS_INPUT && seq->input_normals == TCB_INPUT_NORMALS_GT);
}

const char *tcb_pcgrid_normals_used(void *self, const tcb_sequence *seq)
{
    return tcb_pcgrid_uses_gt_normals(self, seq) ? "gt" : "estimated";
}

/* ---- the inputs of an optimisation, rebuilt identically by fit and load ---- */

static void inputs_free(const tcb_pcgrid_method *b, tcb_pcgrid_inputs *in)
{
    if (in->problem) b->hooks->problem_free(in->problem);
    free(in->problem);
    tcb_pcgrid_clouds_free(&in->clouds);
    memset(in, 0, sizeof *in);
}

/* The clouds (stream (seed, "<name>/points")) mapped into the cube by
 * f->map, the keyframe, its template into f->template_mesh, and the
 * method's problem over them. */
static int prepare(tcb_pcgrid_method *b, const tcb_sequence *seq, uint64_t seed, tcb_pcgrid_fitted *f,
                   tcb_pcgrid_inputs *in, tcb_error *err)
{
    const tcb_pcgrid_hooks *h = b->hooks;
    memset(in, 0, sizeof *in);
    tcb_mesh_free(&f->template_mesh);
    b->spec.gt_normals = tcb_pcgrid_uses_gt_normals(b, seq);
    b->spec.seed = seed;
    char stream[64];
    snprintf(stream, sizeof stream, "%s/points", h->name);
    int rc = tcb_pcgrid_clouds_draw(seq, b->points, seed, stream, h->frame_map, &f->map, &in->clouds, err);
    tcb_pcgrid_clouds *c = &in->clouds;
    const float *const *clouds = (const float *const *)c->clouds;
    in->map = &f->map;
    if (!rc)
        rc = h->keyframe ? h->keyframe(clouds, c->n, c->T, &in->key, err)
                         : tcb_pcgrid_keyframe(clouds, c->n, c->T, b->keyframe_res, &in->key, err);
    if (!rc && !h->trained_template) {
        rc = tcb_pcgrid_template_build(seq, in->key, &f->map, c->clouds[in->key], c->n[in->key], &b->spec,
                                       &f->template_mesh, err);
        in->template_mesh = &f->template_mesh;
    }
    if (!rc && !(in->problem = calloc(1, h->problem_size))) rc = tcb_fail(err, TCB_ERR_NOMEM, "out of memory");
    if (!rc) rc = h->problem_init(b, seq, in, err);
    if (rc) {
        inputs_free(b, in);
        tcb_error_prefix(err, "%s: ", h->name);
    }
    return rc;
}

/* ---- a trainer over the inputs ---- */

typedef struct trainer {
    void *state;                 /* hooks->trainer_size bytes */
    uint64_t seed;
    const tcb_pcgrid_hooks *hooks;
} trainer;

static int trainer_init(const tcb_pcgrid_method *b, const tcb_pcgrid_inputs *in, uint64_t seed, trainer *t,
                        tcb_error *err)
{
    *t = (trainer){calloc(1, b->hooks->trainer_size), seed, b->hooks};
    if (!t->state) return tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", b->hooks->name);
    int rc = b->hooks->trainer_init(t->state, b, in->problem, seed, err);
    if (rc) b->hooks->trainer_free(t->state), free(t->state), t->state = NULL;
    return rc;
}

static void trainer_free(trainer *t)
{
    if (t->state) t->hooks->trainer_free(t->state);
    free(t->state);
    t->state = NULL;
}

static int loop_step(void *t, double *loss, tcb_error *err)
{
    trainer *s = t;
    return s->hooks->step(s->state, loss, err);
}

static long long loop_done(const void *t)
{
    const trainer *s = t;
    return s->hooks->done(s->state);
}

static int loop_save(const void *t, double seconds, const char *path, tcb_error *err)
{
    const trainer *s = t;
    return s->hooks->save(s->state, s->seed, seconds, path, err);
}

static int loop_load(void *t, const char *path, double *seconds, tcb_error *err)
{
    trainer *s = t;
    return s->hooks->load(s->state, s->seed, path, seconds, err);
}

/* The fitted model of t's parameters: a copy of them (for save) and the
 * template (the trainer's own, for a method that makes it) carried into
 * every one of the inputs' frames. */
static int keep_model(tcb_pcgrid_method *b, const tcb_pcgrid_inputs *in, const trainer *t, tcb_error *err)
{
    if (b->hooks->trained_template) {
        tcb_mesh_free(&b->fitted.template_mesh);
        int rc = b->hooks->trained_template(t->state, &b->fitted.template_mesh, err);
        if (rc) return rc;
    }
    size_t n = 0;
    const float *params = b->hooks->params(t->state, &n);
    free(b->params), free(b->fitted.deformed);
    b->n_params = n;
    b->fitted.n_frames = in->clouds.T;
    b->params = malloc(n * sizeof *b->params);
    b->fitted.deformed = malloc((size_t)in->clouds.T * (size_t)b->fitted.template_mesh.n_verts * 3 * sizeof(float));
    if (!b->params || !b->fitted.deformed) return tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", b->hooks->name);
    memcpy(b->params, params, n * sizeof *b->params);
    return b->hooks->frames(t->state, b->fitted.deformed, err);
}

static void release_model(tcb_pcgrid_method *b)
{
    free(b->params);
    b->params = NULL, b->n_params = 0;
    tcb_pcgrid_fitted_release(&b->fitted);
}

/* ---- train_steps' training (tcbench calibrate, the dry run) ---- */

struct tcb_pcgrid_steps {
    tcb_pcgrid_inputs in;
    trainer t;
    int in_main_phase; /* 0 after a unit of hooks->run_unit moved the trainer */
};

static void steps_free(tcb_pcgrid_method *b)
{
    if (!b->steps) return;
    trainer_free(&b->steps->t);
    inputs_free(b, &b->steps->in);
    free(b->steps);
    b->steps = NULL;
}

void tcb_pcgrid_destroy(void *self)
{
    tcb_pcgrid_method *b = self;
    if (!b) return;
    steps_free(b);
    release_model(b);
    free(b);
}

/* ---- fit ---- */

int tcb_pcgrid_fit(void *self, const tcb_sequence *seq, const tcb_fit_ctx *ctx, tcb_error *err)
{
    tcb_pcgrid_method *b = self;
    steps_free(b);
    release_model(b);
    b->seed = ctx->seed;
    tcb_pcgrid_inputs in;
    trainer t = {0};
    int made_later = b->hooks->trained_template != NULL;
    int rc = prepare(b, seq, ctx->seed, &b->fitted, &in, err);
    if (!rc && !made_later)
        rc = tcb_pcgrid_template_write(&b->fitted.template_mesh, &b->fitted.map, ctx->work_dir, in.key, err);
    if (!rc && b->hooks->describe) {
        char line[256];
        b->hooks->describe(in.problem, line, sizeof line);
        tcb_report_log(&ctx->reporter, TCB_LOG_INFO, "%s: %s", b->hooks->name, line);
    }
    if (!rc) rc = trainer_init(b, &in, ctx->seed, &t, err);
    if (!rc) {
        tcb_train_loop loop = {.name = b->hooks->name, .iterations = b->epochs,
                               .checkpoint_every = b->checkpoint_every, .ckpt_name = CKPT_NAME, .trainer = &t,
                               .step = loop_step, .done = loop_done, .save = loop_save, .load = loop_load};
        rc = tcb_train_loop_run(&loop, ctx, err);
    }
    if (!rc) rc = keep_model(b, &in, &t, err);
    if (!rc && made_later)
        rc = tcb_pcgrid_template_write(&b->fitted.template_mesh, &b->fitted.map, ctx->work_dir, in.key, err);
    trainer_free(&t);
    inputs_free(b, &in);
    return rc;
}

/* ---- read-out ---- */

/* The model of train_steps' epochs, once they stopped; nothing without. */
static int steps_model(tcb_pcgrid_method *b, tcb_error *err)
{
    if (!b->steps || b->fitted.deformed) return TCB_OK;
    return keep_model(b, &b->steps->in, &b->steps->t, err);
}

int tcb_pcgrid_transfer_op(void *self, const tcb_sequence *seq, int i, int j, const float *src, int n, float *out,
                           tcb_rng *rng, tcb_error *err)
{
    (void)rng; /* deterministic: the fitted frames */
    tcb_pcgrid_method *b = self;
    int rc = steps_model(b, err);
    return rc ? rc : tcb_pcgrid_transfer(&b->fitted, seq, i, j, src, n, out, err);
}

int tcb_pcgrid_reconstruct_op(void *self, const tcb_sequence *seq, int i, int j, int frame, tcb_rng *rng,
                              float **pts, int *n, tcb_error *err)
{
    tcb_pcgrid_method *b = self;
    *pts = NULL;
    int rc = steps_model(b, err);
    return rc ? rc : tcb_pcgrid_reconstruct(&b->fitted, seq, i, j, frame, b->recon_points, rng, pts, n, err);
}

/* The template carried to `frame`, in the sequence's coordinates, without
 * charts (tcb/method.h: a template moved into every frame needs none); the
 * same faces in every frame. */
int tcb_pcgrid_surface_op(void *self, const tcb_sequence *seq, int frame, tcb_rng *rng, tcb_uv_mesh *out,
                          tcb_error *err)
{
    (void)rng;
    tcb_pcgrid_method *b = self;
    const tcb_uv_mesh none = {0, 0, 0, NULL, NULL, NULL, NULL};
    *out = none;
    int rc = steps_model(b, err);
    return rc ? rc : tcb_pcgrid_surface(&b->fitted, seq, frame, out, err);
}

/* ---- the model file: the parameters under the method's manifest ---- */

int tcb_pcgrid_save(void *self, const char *path, tcb_error *err)
{
    tcb_pcgrid_method *b = self;
    if (!b->params) return tcb_fail(err, TCB_ERR_INTERNAL, "%s: %s saved before fit", path, b->hooks->name);
    cJSON *j = b->hooks->manifest(b, b->n_params);
    tcb_weight_parts w = {1, {b->params, NULL}, {b->n_params, 0}};
    int rc = tcb_model_file_write(path, b->hooks->magic, b->seed, j, &w, err);
    cJSON_Delete(j);
    return rc;
}

/* The file's seed rebuilds the inputs and a trainer (whose parameter count
 * may follow from the template: PDG's); the file's parameters replace the
 * trainer's. */
int tcb_pcgrid_load(void *self, const tcb_sequence *seq, const char *path, tcb_error *err)
{
    tcb_pcgrid_method *b = self;
    steps_free(b);
    release_model(b);
    tcb_pcgrid_inputs in;
    memset(&in, 0, sizeof in);
    trainer t = {0};
    uint64_t seed = 0;
    int rc = tcb_model_file_seed(path, b->hooks->magic, &seed, err);
    if (!rc) rc = prepare(b, seq, seed, &b->fitted, &in, err);
    if (!rc) rc = trainer_init(b, &in, seed, &t, err);
    if (!rc) {
        size_t n = 0;
        float *params = b->hooks->params(t.state, &n);
        cJSON *want = b->hooks->manifest(b, n);
        tcb_weight_parts w = {1, {params, NULL}, {n, 0}};
        rc = tcb_model_file_read(path, b->hooks->magic, want, &seed, &w, err);
        cJSON_Delete(want);
    }
    if (!rc) rc = keep_model(b, &in, &t, err);
    trainer_free(&t);
    inputs_free(b, &in);
    if (rc) release_model(b);
    else b->seed = seed;
    return rc;
}

/* ---- calibration ---- */

/* train_steps' training, started by the first call of train_steps or of
 * a unit of the method's own (the inputs and template a fit builds first). */
static int steps_start(tcb_pcgrid_method *b, const tcb_sequence *seq, const tcb_fit_ctx *ctx, tcb_error *err)
{
    if (b->steps) return TCB_OK;
    release_model(b);
    b->seed = ctx->seed;
    if (!(b->steps = calloc(1, sizeof *b->steps)))
        return tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", b->hooks->name);
    int rc = prepare(b, seq, ctx->seed, &b->fitted, &b->steps->in, err);
    if (!rc) rc = trainer_init(b, &b->steps->in, ctx->seed, &b->steps->t, err);
    if (rc) steps_free(b);
    return rc;
}

/* The model of fewer epochs than a fit's is dropped after each timed call:
 * a read-out rebuilds it (steps_model), so that the timed calls are steps
 * only. */
static void drop_model(tcb_pcgrid_method *b)
{
    free(b->fitted.deformed), free(b->params);
    b->fitted.deformed = NULL, b->params = NULL;
}

/* tcb_method_ops.train_steps: fit's training n epochs at a time, in its
 * main phase (hooks->main_phase, again after a unit moved the trainer). */
int tcb_pcgrid_train_steps(void *self, const tcb_sequence *seq, const tcb_fit_ctx *ctx, long long n, tcb_error *err)
{
    tcb_pcgrid_method *b = self;
    int rc = steps_start(b, seq, ctx, err);
    if (rc) return rc;
    if (!b->steps->in_main_phase && b->hooks->main_phase) b->hooks->main_phase(b->steps->t.state);
    b->steps->in_main_phase = 1;
    double loss;
    for (long long k = 0; !rc && k < n; k++) rc = b->hooks->step(b->steps->t.state, &loss, err);
    drop_model(b);
    return rc;
}

const tcb_pcgrid_inputs *tcb_pcgrid_steps_inputs(const void *self, const void **trainer)
{
    const tcb_pcgrid_method *b = self;
    if (trainer) *trainer = b->steps ? b->steps->t.state : NULL;
    return b->steps ? &b->steps->in : NULL;
}

/* tcb_method_ops.run_unit: "template", the inputs and template mesh a fit
 * (and a load) builds before its first epoch: the clouds, the keyframe,
 * its template and the method's problem. Built aside, so that a training
 * of train_steps keeps its own. A later unit is the method's own
 * (hooks->run_unit), on train_steps' trainer. */
int tcb_pcgrid_run_unit(void *self, const tcb_sequence *seq, const tcb_fit_ctx *ctx, int unit, tcb_error *err)
{
    tcb_pcgrid_method *b = self;
    if (unit != UNIT_TEMPLATE) {
        if (!b->hooks->run_unit) return tcb_fail(err, TCB_ERR_INTERNAL, "%s: no unit %d", b->hooks->name, unit);
        int rc = steps_start(b, seq, ctx, err);
        if (rc) return rc;
        b->steps->in_main_phase = 0;
        rc = b->hooks->run_unit(b->steps->t.state, unit, err);
        drop_model(b);
        return rc;
    }
    tcb_pcgrid_fitted aside = {.method = b->hooks->name};
    tcb_pcgrid_inputs in;
    int rc = prepare(b, seq, ctx->seed, &aside, &in, err);
    inputs_free(b, &in);
    tcb_pcgrid_fitted_release(&aside);
    return rc;
}

void tcb_pcgrid_estimate(const tcb_pcgrid_method *b, const char *const *presets, int k, tcb_cost_estimate *out)
{
    tcb_step_cost_estimate(b->hooks->name, presets, k, b->epochs, out);
    out->step_frames = 1;
    if (k >= 0) out->units[out->n_units++] = (tcb_unit_use){"template", 1, 0, 0, 0};
}
