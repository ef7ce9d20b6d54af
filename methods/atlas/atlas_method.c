/* atlasnet, dsr and mca: one network and training loop (model.h,
 * train.h), three method tables that differ only in the loss.
 *
 * Presets (overridable key by key; the default is cpu):
 *   paper  C 1024, P 10, M 2500, 200,000 iterations (reference-protocol §4)
 *   cpu    C 256,  P 10, M 1000,  40,000 iterations (sized for 2 CPU cores)
 *   tiny   C 32,   P 4,  M 200,      300 iterations (tests)
 *
 * Two kinds of checkpoint. During fit, every `checkpoint_every` iterations
 * the whole training state goes to <work_dir>/train.ckpt (train_ckpt.h,
 * through neural/train_loop.h); a fit that finds one continues from it,
 * bit-identical to an uninterrupted training, and deletes it when done. After fit the harness saves the
 * trained weights through save/load below. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "methods/atlas/eval.h"
#include "methods/atlas/surface.h"
#include "methods/atlas/train.h"
#include "methods/atlas/train_ckpt.h"
#include "methods/builtin.h"
#include "methods/params.h"
#include "methods/step_cost.h"
#include "neural/train_loop.h"
#include "tcb/json.h"
#include "tcb/metrics.h"

typedef struct atlas_preset {
    int C, P, M;
    long long iterations;
} atlas_preset;

static const atlas_preset presets[] = {
    {1024, 10, 2500, 200000},
    {256, 10, 1000, 40000},
    {32, 4, 200, 300},
};
static const char *const preset_names[] = {"paper", "cpu", "tiny", NULL}; /* presets[k]; default cpu */
static const char *const pair_names[] = {"neighbors", "random", NULL};     /* training pairs; Table 2 */

typedef struct atlas_method {
    const char *name;           /* the method's, for messages */
    int preset;                 /* presets[preset]; -1 when a size differs from it */
    int C, P;
    tcb_atlas_train_cfg cfg;
    long long checkpoint_every; /* iterations between training checkpoints; 0: none */
    uint64_t seed;              /* of the fit: the UV cache's stream */
    tcb_atlas_model *model;     /* NULL before fit or load */
    tcb_atlas_trainer *steps;   /* train_steps' training of model; NULL: none */
    tcb_atlas_eval_state eval; /* UV sets and workspaces of the evaluation */
    const tcb_sequence *last_seq; /* the last pair evaluated: (last_seq, last_i, last_j) */
    int last_i, last_j, n_pred;
    float *pred;                /* [2][n_pred][3] its predictions of frames i and j */
} atlas_method;

static int parse(const char *params_json, const char *where, atlas_method *a, tcb_error *err)
{
    static const char *const keys[] = {"preset", "iterations", "latent", "patches", "uv_samples",
                                       "alpha_mc", "alpha_sciso", "pairs", "delta", "lr", "checkpoint_every",
                                       "divergence", NULL};
    cJSON *j;
    int rc = tcb_params_parse(params_json, where, keys, &j, err);
    if (rc) return rc;
    int pi = 0;
    long long it = 0, C = 0, P = 0, M = 0, delta = 0;
    tcb_atlas_train_cfg *c = &a->cfg;
    rc = tcb_json_enum(j, "preset", where, 0, 1, preset_names, &pi, err);
    const atlas_preset *pr = &presets[pi];
    if (!rc) rc = tcb_json_int(j, "iterations", where, 0, pr->iterations, 1, 100000000, &it, err);
    if (!rc) rc = tcb_json_int(j, "latent", where, 0, pr->C, 1, 65536, &C, err);
    if (!rc) rc = tcb_json_int(j, "patches", where, 0, pr->P, 1, 1000, &P, err);
    if (!rc) rc = tcb_json_int(j, "uv_samples", where, 0, pr->M, 1, 10000000, &M, err);
    if (!rc) rc = tcb_json_num(j, "alpha_mc", where, 0, 0.1, 0, 1e6, &c->alpha_mc, err);
    if (!rc) rc = tcb_json_num(j, "alpha_sciso", where, 0, 0.001, 0, 1e6, &c->alpha_sciso, err);
    int pairs = 0;
    if (!rc) rc = tcb_json_enum(j, "pairs", where, 0, 0, pair_names, &pairs, err);
    if (!rc) rc = tcb_json_int(j, "delta", where, 0, 1, 1, 1000000, &delta, err);
    if (!rc) rc = tcb_json_num(j, "lr", where, 0, 1e-3, 1e-12, 10, &c->lr, err);
    if (!rc) rc = tcb_json_int(j, "checkpoint_every", where, 0, 1000, 0, 100000000, &a->checkpoint_every, err);
    if (!rc) rc = tcb_json_num(j, "divergence", where, 0, 1e4, 0, 1e300, &c->divergence, err);
    cJSON_Delete(j);
    if (rc) return rc;
    if (M % P)
        return tcb_fail(err, TCB_ERR_INPUT, "%s: uv_samples %lld must be a multiple of patches %lld", where, M,
                        P);
    a->C = (int)C, a->P = (int)P;
    a->preset = C == pr->C && P == pr->P && M == pr->M ? pi : -1;
    c->M = (int)M, c->iterations = it, c->delta = (int)delta;
    c->pairs = pairs ? TCB_PAIRS_RANDOM : TCB_PAIRS_NEIGHBORS;
    return TCB_OK;
}

static int create(const char *name, tcb_atlas_loss loss, const char *params_json, void **self,
                  tcb_error *err)
{
    *self = NULL;
    char where[64];
    snprintf(where, sizeof where, "%s.params", name);
    atlas_method *a = calloc(1, sizeof *a);
    if (!a) return tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", name);
    a->name = name, a->cfg.loss = loss, a->last_i = a->last_j = -1;
    int rc = parse(params_json, where, a, err);
    if (rc) {
        free(a);
        return rc;
    }
    *self = a;
    return TCB_OK;
}

static void forget_pair(atlas_method *a)
{
    free(a->pred);
    a->pred = NULL, a->n_pred = 0, a->last_seq = NULL, a->last_i = a->last_j = -1;
}

/* A fresh model initialised from (seed, "atlas/init"). */
static int new_model(atlas_method *a, uint64_t seed, tcb_error *err)
{
    tcb_atlas_trainer_free(a->steps); /* it trains the model freed here */
    a->steps = NULL;
    tcb_atlas_model_free(a->model);
    a->model = NULL;
    forget_pair(a);
    tcb_atlas_eval_state_free(&a->eval);
    tcb_atlas_eval_state_init(&a->eval, seed);
    a->seed = seed;
    int rc = tcb_atlas_model_create(a->C, a->P, &a->model, err);
    if (rc) return rc;
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, seed, "atlas/init");
    tcb_atlas_model_init(a->model, &rng);
    return TCB_OK;
}

/* The training loop's view of an atlas training (neural/train_loop.h). */
typedef struct atlas_fit {
    tcb_atlas_trainer *t;
    const tcb_sequence *seq;
    uint64_t seed;
} atlas_fit;

static int fit_step(void *f, double *loss, tcb_error *err)
{
    atlas_fit *a = f;
    return tcb_atlas_train_step(a->t, a->seq, loss, err);
}

static long long fit_done(const void *f) { return ((const atlas_fit *)f)->t->it; }

static int fit_save(const void *f, double seconds, const char *path, tcb_error *err)
{
    const atlas_fit *a = f;
    return tcb_atlas_train_ckpt_save(a->t, a->seq, a->seed, seconds, path, err);
}

static int fit_load(void *f, const char *path, double *seconds, tcb_error *err)
{
    atlas_fit *a = f;
    return tcb_atlas_train_ckpt_load(a->t, a->seq, a->seed, path, seconds, err);
}

/* Trains with ctx->n_threads OpenMP threads; the evaluation runs with the
 * process's setting, as it gets no ctx. */
static int fit(void *self, const tcb_sequence *seq, const tcb_fit_ctx *ctx, tcb_error *err)
{
    atlas_method *a = self;
    atlas_fit f = {.seq = seq, .seed = ctx->seed};
    int rc = new_model(a, ctx->seed, err);
    if (!rc) rc = tcb_atlas_trainer_create(&a->cfg, a->model, seq, ctx->seed, &f.t, err);
    if (rc) {
        tcb_error_prefix(err, "%s: ", a->name);
        return rc;
    }
    tcb_train_loop loop = {.name = a->name, .iterations = a->cfg.iterations, .checkpoint_every = a->checkpoint_every,
                           .ckpt_name = TCB_ATLAS_TRAIN_CKPT, .trainer = &f, .step = fit_step, .done = fit_done,
                           .save = fit_save, .load = fit_load};
    rc = tcb_train_loop_run(&loop, ctx, err);
    tcb_atlas_trainer_free(f.t);
    return rc;
}

/* A fitted model and frames i, j of seq with point pools to draw from. */
static int check_frames(const atlas_method *a, const tcb_sequence *seq, int i, int j, tcb_error *err)
{
    if (!a->model) return tcb_fail(err, TCB_ERR_INTERNAL, "%s: evaluation before fit or load", a->name);
    if (i < 0 || j < 0 || i >= seq->n_frames || j >= seq->n_frames || seq->pool_size < 1 || seq->input_points < 1)
        return tcb_fail(err, TCB_ERR_INPUT, "%s: pair %d->%d outside frames 0..%d or no point pools", a->name, i,
                        j, seq->n_frames - 1);
    return TCB_OK;
}

/* Evaluates pair (i, j) with fresh input clouds from rng, unless it is the
 * pair evaluated last. */
static int eval_pair(atlas_method *a, const tcb_sequence *seq, int i, int j, tcb_rng *rng,
                     tcb_error *err)
{
    int rc = check_frames(a, seq, i, j, err);
    if (rc) return rc;
    if (a->pred && a->last_seq == seq && a->last_i == i && a->last_j == j) return TCB_OK;
    forget_pair(a);
    int N = seq->input_points;
    float *clouds = malloc((size_t)2 * N * 3 * sizeof *clouds);
    if (!clouds) return tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", a->name);
    rc = tcb_sequence_draw_points(seq, i, N, seq->draw_with_replacement, rng, clouds, err);
    if (!rc) rc = tcb_sequence_draw_points(seq, j, N, seq->draw_with_replacement, rng, clouds + (size_t)N * 3, err);
    if (!rc) rc = tcb_atlas_eval_pair(a->model, &a->eval, clouds, N, &a->pred, &a->n_pred, err);
    free(clouds);
    if (!rc) a->last_seq = seq, a->last_i = i, a->last_j = j;
    return rc;
}

static int transfer(void *self, const tcb_sequence *seq, int i, int j, const float *src, int n, float *out,
                    tcb_rng *rng, tcb_error *err)
{
    atlas_method *a = self;
    int rc = eval_pair(a, seq, i, j, rng, err);
    if (rc) return rc;
    return tcb_atlas_transfer(src, n, a->pred, a->pred + (size_t)a->n_pred * 3, a->n_pred, out, err);
}

static int reconstruct(void *self, const tcb_sequence *seq, int i, int j, int frame, tcb_rng *rng, float **pts,
                       int *n, tcb_error *err)
{
    atlas_method *a = self;
    *pts = NULL, *n = 0;
    if (frame != i && frame != j)
        return tcb_fail(err, TCB_ERR_INPUT, "%s: frame %d is not in pair %d->%d", a->name, frame, i, j);
    int rc = eval_pair(a, seq, i, j, rng, err);
    if (rc) return rc;
    size_t len = (size_t)a->n_pred * 3 * sizeof **pts;
    *pts = malloc(len);
    if (!*pts) return tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", a->name);
    memcpy(*pts, a->pred + (frame == i ? 0 : (size_t)a->n_pred * 3), len);
    *n = a->n_pred;
    return TCB_OK;
}

/* Every patch, collapsed or not (the evaluation drops collapsed ones from
 * a pair's points; here a collapsed patch is a sliver the picture shows as
 * such), on a regular grid decoded for one input cloud of the frame drawn
 * from rng as the evaluation draws a pair's. */
static int surface(void *self, const tcb_sequence *seq, int frame, tcb_rng *rng, tcb_uv_mesh *out, tcb_error *err)
{
    atlas_method *a = self;
    const tcb_uv_mesh none = {0, 0, 0, NULL, NULL, NULL, NULL};
    *out = none;
    int rc = check_frames(a, seq, frame, frame, err);
    if (rc) return rc;
    int N = seq->input_points;
    float *cloud = malloc((size_t)N * 3 * sizeof *cloud);
    if (!cloud) return tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", a->name);
    rc = tcb_sequence_draw_points(seq, frame, N, seq->draw_with_replacement, rng, cloud, err);
    if (!rc) rc = tcb_atlas_surface(a->model, cloud, N, TCB_ATLAS_SURFACE_RES, out, err);
    free(cloud);
    return rc;
}

static void destroy(void *self)
{
    atlas_method *a = self;
    if (!a) return;
    tcb_atlas_trainer_free(a->steps);
    tcb_atlas_model_free(a->model);
    tcb_atlas_eval_state_free(&a->eval);
    free(a->pred);
    free(a);
}

/* ---- checkpoint -----------------------------------------------------------
 * One model file (neural/weights.h) under the magic "TCBATLS1": the fit's
 * seed (the evaluation's UV sets derive from it), the model's manifest and
 * its weights. */
#define MAGIC "TCBATLS1"

static int save(void *self, const char *path, tcb_error *err)
{
    atlas_method *a = self;
    if (!a->model) return tcb_fail(err, TCB_ERR_INTERNAL, "%s: %s saved before fit", path, a->name);
    cJSON *manifest = tcb_atlas_model_manifest(a->model);
    tcb_weight_parts w = tcb_atlas_model_weights(a->model);
    int rc = tcb_model_file_write(path, MAGIC, a->seed, manifest, &w, err);
    cJSON_Delete(manifest);
    return rc;
}

static int load(void *self, const tcb_sequence *seq, const char *path, tcb_error *err)
{
    (void)seq; /* the weights do not depend on which sequence is evaluated */
    atlas_method *a = self;
    uint64_t seed = 0;
    int rc = new_model(a, 0, err);
    if (rc) return rc;
    cJSON *want = tcb_atlas_model_manifest(a->model);
    tcb_weight_parts w = tcb_atlas_model_weights(a->model);
    rc = tcb_model_file_read(path, MAGIC, want, &seed, &w, err);
    cJSON_Delete(want);
    if (!rc) {
        /* the UV sets belong to the fit's seed */
        tcb_atlas_eval_state_free(&a->eval);
        tcb_atlas_eval_state_init(&a->eval, seed);
        a->seed = seed;
    } else {
        tcb_atlas_model_free(a->model);
        a->model = NULL;
    }
    return rc;
}

/* tcb_method_ops.train_steps: fit's training, n steps at a time. */
static int train_steps(void *self, const tcb_sequence *seq, const tcb_fit_ctx *ctx, long long n, tcb_error *err)
{
    atlas_method *a = self;
    int rc = a->steps ? TCB_OK : new_model(a, ctx->seed, err);
    if (!rc && !a->steps) rc = tcb_atlas_trainer_create(&a->cfg, a->model, seq, ctx->seed, &a->steps, err);
    double loss;
    for (long long k = 0; !rc && k < n; k++) rc = tcb_atlas_train_step(a->steps, seq, &loss, err);
    if (rc) tcb_error_prefix(err, "%s: ", a->name);
    return rc;
}

static void estimate(void *self, const tcb_cost_query *q, tcb_cost_estimate *out)
{
    (void)q;
    const atlas_method *a = self;
    tcb_step_cost_estimate(a->name, preset_names, a->preset, a->cfg.iterations, out);
}

/* ---- the three tables ---------------------------------------------------- */

#define ATLAS_METHOD(id, loss, desc)                                                                         \
    static int id##_create(const char *params_json, void **self, tcb_error *err)                             \
    {                                                                                                        \
        return create(#id, loss, params_json, self, err);                                                    \
    }                                                                                                        \
    const tcb_method_ops tcb_method_##id = {                                                                 \
        .abi_version = TCB_METHOD_ABI_VERSION, .name = #id, .description = desc, .create = id##_create,      \
        .fit = fit, .transfer = transfer, .reconstruct = reconstruct, .save = save, .load = load,            \
        .destroy = destroy, .estimate = estimate, .surface = surface, .presets = preset_names,               \
        .train_steps = train_steps,                                                                          \
    };

ATLAS_METHOD(atlasnet, TCB_ATLAS_LOSS_CHAMFER, "AtlasNet: PointNet + patch decoders, Chamfer loss only")
ATLAS_METHOD(dsr, TCB_ATLAS_LOSS_DSR, "DSR: AtlasNet + scaled-isometry and total-area terms (alpha_sciso 0.001)")
ATLAS_METHOD(mca, TCB_ATLAS_LOSS_METRIC, "MCA: AtlasNet + metric consistency between neighbour frames (alpha_mc 0.1)")
