/* neupig: Neural Preconditioned Grids (Neu-PiG, CVPR 2026): one template,
 * the keyframe's screened Poisson surface decimated to a triangle budget
 * (tcb/meshing.h), moved into every frame by a per-vertex rigid motion
 * that an MLP reads from preconditioned feature grids and the frame's time
 * (methods/neupig/model.h), optimised per sequence on the frames' point
 * clouds (methods/neupig/train.h). docs/protocol.md, "Neu-PiG", lists the
 * reference files followed and every difference.
 *
 * Params (presets overridable key by key; default cpu):
 *   preset   paper (1 000 epochs, 5 000 points a frame, 20 000 triangles,
 *            depth 10, the reference's network), fast (the paper's
 *            250-epoch variant), cpu (the paper's 1 000 epochs at sizes
 *            for 2 cores: docs/protocol.md, "Neu-PiG"), tiny (tests)
 *   normals  input (default: the normals the sequence's input comes with,
 *            "evaluation.input_normals", estimated when it comes with none)
 *            | estimated (PCA, oriented) | gt (the reference's setting:
 *            the ground-truth face normal at each keyframe point)
 *   epochs, points, template_faces, poisson_depth, levels, features,
 *   hidden, recon_points, checkpoint_every, divergence
 *
 * Read-out (transfer i → j): each source point, in the method's cube, is
 * located on the template deformed to frame i (closest surface point,
 * barycentric coordinates: tcb/locate.h) and carried to the same point of
 * the template deformed to frame j; the harness projects it onto j's GT
 * vertices. reconstruct samples the deformed template's surface; surface
 * returns that mesh itself, without charts (tcb/method.h: a template moved
 * into every frame needs none, its vertices mark the same points in every
 * frame), for the reconstruction metrics and `tcbench frames`.
 *
 * Checkpoints: the whole optimisation state in <work_dir>/train.ckpt
 * (continued bit-identically); the model file holds the parameters and the
 * fit's seed, and load rebuilds the template from the sequence with that
 * seed (the clouds, keyframe, normals and Poisson surface are
 * deterministic) rather than storing it. */
#include <stdlib.h>
#include <string.h>

#include "methods/builtin.h"
#include "methods/pcgrid/fitted.h"
#include "methods/pcgrid/template.h"
#include "methods/neupig/train.h"
#include "methods/params.h"
#include "methods/step_cost.h"
#include "neural/train_loop.h"
#include "neural/weights.h"
#include "tcb/geometry.h"
#include "tcb/json.h"
#include "tcb/locate.h"
#include "tcb/meshing.h"

#define CKPT_NAME "train.ckpt"
#define MAGIC "TCBNPIG2"

typedef struct neupig_preset {
    long long epochs;
    int points, template_faces, poisson_depth, levels, features, hidden;
} neupig_preset;

static const neupig_preset presets[] = {
    {1000, 5000, 20000, 10, 8, 30, 512}, /* paper */
    {250, 5000, 20000, 10, 8, 30, 512},  /* fast */
    {1000, 2500, 5000, 8, 6, 16, 128},   /* cpu */
    {30, 300, 400, 6, 3, 8, 16},         /* tiny */
};
static const char *const preset_names[] = {"paper", "fast", "cpu", "tiny", NULL};
static const char *const normals_names[] = {"estimated", "gt", "input", NULL};
enum { NORMALS_ESTIMATED, NORMALS_GT, NORMALS_INPUT };
/* The presets `tcbench calibrate` measures: fast has paper's sizes (its
 * epochs cost what paper's do), so paper's step prices it. */
static const char *const calibrated_presets[] = {"paper", "cpu", "tiny", NULL};
static const char *const unit_names[] = {"template", NULL};
enum { UNIT_TEMPLATE };
#define DEFAULT_RECON_POINTS 2500

struct steps;

typedef struct neupig_method {
    tcb_neupig_arch arch;
    tcb_neupig_schedule sched;
    int points, template_faces, poisson_depth, recon_points;
    int normals;                   /* NORMALS_*: the "normals" param */
    int gt_normals;                /* the keyframe's normals are GT's: resolved on the sequence */
    long long checkpoint_every;
    uint64_t seed;
    /* The fitted model (after fit or load). */
    float *params;                 /* [n_params] */
    tcb_pcgrid_fitted fitted;      /* the cube's map, the template and its frames */
    struct steps *steps;           /* train_steps' training; NULL: none */
} neupig_method;

static int parse(const char *params_json, void *obj, tcb_error *err)
{
    neupig_method *m = obj;
    static const char *const keys[] = {"preset", "normals", "epochs", "points", "template_faces", "poisson_depth",
                                       "levels", "features", "hidden", "recon_points", "checkpoint_every",
                                       "divergence", "laplacian", NULL};
    const char *where = "neupig.params";
    cJSON *j;
    int rc = tcb_params_parse(params_json, where, keys, &j, err);
    if (rc) return rc;
    int pi = 2, ni = NORMALS_INPUT, li = TCB_SOBOLEV_PCGRID;
    long long epochs, points, faces, depth, levels, features, hidden, recon;
    rc = tcb_json_enum(j, "preset", where, 0, 2, preset_names, &pi, err);
    if (!rc) rc = tcb_json_enum(j, "normals", where, 0, NORMALS_INPUT, normals_names, &ni, err);
    if (!rc) rc = tcb_json_enum(j, "laplacian", where, 0, TCB_SOBOLEV_PCGRID, tcb_sobolev_laplacian_names, &li, err);
    const neupig_preset *p = &presets[pi];
    if (!rc) rc = tcb_json_int(j, "epochs", where, 0, p->epochs, 1, 100000000, &epochs, err);
    if (!rc) rc = tcb_json_int(j, "points", where, 0, p->points, 4, 10000000, &points, err);
    if (!rc) rc = tcb_json_int(j, "template_faces", where, 0, p->template_faces, 4, 10000000, &faces, err);
    if (!rc) rc = tcb_json_int(j, "poisson_depth", where, 0, p->poisson_depth, TCB_POISSON_DEPTH_MIN,
                                TCB_POISSON_DEPTH_MAX, &depth, err);
    if (!rc) rc = tcb_json_int(j, "levels", where, 0, p->levels, 1, TCB_NEUPIG_MAX_LEVELS, &levels, err);
    if (!rc) rc = tcb_json_int(j, "features", where, 0, p->features, 1, 4096, &features, err);
    if (!rc) rc = tcb_json_int(j, "hidden", where, 0, p->hidden, 1, 65536, &hidden, err);
    if (!rc) rc = tcb_json_int(j, "recon_points", where, 0, DEFAULT_RECON_POINTS, 1, 10000000, &recon, err);
    if (!rc) rc = tcb_json_int(j, "checkpoint_every", where, 0, 50, 0, 100000000, &m->checkpoint_every, err);
    if (!rc) rc = tcb_json_num(j, "divergence", where, 0, 1e4, 0, 1e300, &m->sched.divergence, err);
    cJSON_Delete(j);
    if (rc) return rc;
    m->arch = tcb_neupig_arch_reference();
    m->arch.levels = (int)levels, m->arch.features = (int)features, m->arch.hidden = (int)hidden;
    m->arch.laplacian = (tcb_sobolev_laplacian)li;
    m->fitted.method = "neupig";
    m->sched.epochs = epochs, m->sched.lr_grid = 0.005, m->sched.lr_growth = 2.5, m->sched.lr_mlp = 1e-3;
    m->points = (int)points, m->template_faces = (int)faces, m->poisson_depth = (int)depth;
    m->normals = ni, m->recon_points = (int)recon;
    return TCB_OK;
}

static void release_model(neupig_method *m)
{
    free(m->params);
    m->params = NULL;
    tcb_pcgrid_fitted_release(&m->fitted);
}

static int create(const char *params_json, void **self, tcb_error *err)
{
    return tcb_method_create(sizeof(neupig_method), "neupig", params_json, parse, NULL, self, err);
}

static void steps_free(neupig_method *m);

static void destroy(void *self)
{
    neupig_method *m = self;
    if (!m) return;
    steps_free(m);
    release_model(m);
    free(m);
}

/* ---- the inputs of an optimisation, rebuilt identically by fit and load ---- */

typedef struct inputs {
    tcb_pcgrid_clouds c;
    float *vnormals;     /* [nv][3] the template's vertex normals */
    int32_t *edges;      /* [ne][2] */
    float *edge_len;     /* [ne] */
    int ne, key;
    tcb_neupig_problem problem;
} inputs;

static void inputs_free(inputs *in)
{
    tcb_pcgrid_clouds_free(&in->c);
    free(in->vnormals), free(in->edges), free(in->edge_len);
    memset(in, 0, sizeof *in);
}

/* Whether the keyframe's normals are GT's on seq: the "normals" param, or
 * under "input" the sequence's input normals. */
static int uses_gt_normals(const neupig_method *m, const tcb_sequence *seq)
{
    return m->normals == NORMALS_GT || (m->normals == NORMALS_INPUT && seq->input_normals == TCB_INPUT_NORMALS_GT);
}

static const char *normals_used(void *self, const tcb_sequence *seq)
{
    return uses_gt_normals(self, seq) ? "gt" : "estimated";
}

static int prepare(neupig_method *m, const tcb_sequence *seq, uint64_t seed, inputs *in, tcb_error *err)
{
    memset(in, 0, sizeof *in);
    tcb_mesh_free(&m->fitted.template_mesh);
    m->gt_normals = uses_gt_normals(m, seq);
    /* every frame's cloud of m->points, stream (seed, "neupig/points") */
    int rc = tcb_pcgrid_clouds_draw(seq, m->points, seed, "neupig/points", &m->fitted.map, &in->c, err);
    if (!rc)
        rc = tcb_pcgrid_keyframe((const float *const *)in->c.clouds, in->c.n, in->c.T, TCB_PCGRID_KEYFRAME_RES, &in->key, err);
    const tcb_pcgrid_template_spec spec = {
        .gt_normals = m->gt_normals, .poisson_depth = m->poisson_depth, .template_faces = m->template_faces};
    if (!rc)
        rc = tcb_pcgrid_template_build(seq, in->key, &m->fitted.map, in->c.clouds[in->key], in->c.n[in->key], &spec,
                                       &m->fitted.template_mesh, err);
    const tcb_mesh *t = &m->fitted.template_mesh;
    if (!rc) rc = tcb_pcgrid_template_normals(t, &in->vnormals, err);
    if (!rc) rc = tcb_pcgrid_template_edges(t, &in->edges, &in->edge_len, &in->ne, err);
    if (!rc)
        in->problem = (tcb_neupig_problem){t->n_verts, t->verts, in->vnormals, in->ne, in->edges, in->edge_len,
                                           in->c.T, (const float *const *)in->c.clouds, in->c.n,
                                           (const tcb_nn *const *)in->c.index, in->key};
    if (rc) tcb_error_prefix(err, "neupig: ");
    return rc;
}

/* The template deformed into every frame, from m->params. */
static int deform_all(neupig_method *m, const inputs *in, tcb_error *err)
{
    tcb_neupig_model model;
    free(m->fitted.deformed);
    m->fitted.n_frames = in->c.T;
    m->fitted.deformed = malloc((size_t)in->c.T * (size_t)m->fitted.template_mesh.n_verts * 3 * sizeof(float));
    if (!m->fitted.deformed) return tcb_fail(err, TCB_ERR_NOMEM, "neupig: out of memory");
    int rc = tcb_neupig_model_init(&model, &m->arch, err);
    if (!rc) rc = tcb_neupig_deform(&model, m->params, &in->problem, m->fitted.deformed, err);
    tcb_neupig_model_free(&model);
    return rc;
}

/* ---- fit ---- */

static int fit_step(void *t, double *loss, tcb_error *err) { return tcb_neupig_train_step(t, loss, err); }
static long long fit_done(const void *t) { return ((const tcb_neupig_trainer *)t)->it; }

typedef struct fit_state {
    tcb_neupig_trainer trainer;
    uint64_t seed;
} fit_state;

static int fit_save(const void *f, double seconds, const char *path, tcb_error *err)
{
    const fit_state *s = f;
    return tcb_neupig_train_save(&s->trainer, s->seed, seconds, path, err);
}

static int fit_load(void *f, const char *path, double *seconds, tcb_error *err)
{
    fit_state *s = f;
    return tcb_neupig_train_load(&s->trainer, s->seed, path, seconds, err);
}

static int fit(void *self, const tcb_sequence *seq, const tcb_fit_ctx *ctx, tcb_error *err)
{
    neupig_method *m = self;
    steps_free(m);
    release_model(m);
    m->seed = ctx->seed;
    inputs in;
    fit_state s = {.seed = ctx->seed};
    int rc = prepare(m, seq, ctx->seed, &in, err);
    if (!rc) rc = tcb_pcgrid_template_write(&m->fitted.template_mesh, &m->fitted.map, ctx->work_dir, in.key, err);
    if (!rc) rc = tcb_neupig_trainer_init(&s.trainer, &m->arch, &m->sched, &in.problem, ctx->seed, err);
    if (!rc) {
        tcb_train_loop loop = {.name = "neupig", .iterations = m->sched.epochs, .checkpoint_every = m->checkpoint_every,
                               .ckpt_name = CKPT_NAME, .trainer = &s, .step = fit_step, .done = fit_done,
                               .save = fit_save, .load = fit_load};
        rc = tcb_train_loop_run(&loop, ctx, err);
    }
    if (!rc && !(m->params = malloc(s.trainer.model.n_params * sizeof *m->params)))
        rc = tcb_fail(err, TCB_ERR_NOMEM, "neupig: out of memory");
    if (!rc) {
        memcpy(m->params, s.trainer.params, s.trainer.model.n_params * sizeof *m->params);
        rc = deform_all(m, &in, err);
    }
    tcb_neupig_trainer_free(&s.trainer);
    inputs_free(&in);
    return rc;
}

/* ---- read-out ---- */

static int steps_model(neupig_method *m, tcb_error *err);

static int transfer(void *self, const tcb_sequence *seq, int i, int j, const float *src, int n, float *out,
                    tcb_rng *rng, tcb_error *err)
{
    (void)rng;
    neupig_method *m = self;
    int rc = steps_model(m, err);
    return rc ? rc : tcb_pcgrid_transfer(&m->fitted, seq, i, j, src, n, out, err);
}

static int reconstruct(void *self, const tcb_sequence *seq, int i, int j, int frame, tcb_rng *rng, float **pts,
                       int *n, tcb_error *err)
{
    neupig_method *m = self;
    *pts = NULL;
    int rc = steps_model(m, err);
    return rc ? rc : tcb_pcgrid_reconstruct(&m->fitted, seq, i, j, frame, m->recon_points, rng, pts, n, err);
}

/* The template deformed to `frame`, in the sequence's coordinates, without
 * charts; the same faces in every frame. */
static int surface(void *self, const tcb_sequence *seq, int frame, tcb_rng *rng, tcb_uv_mesh *out, tcb_error *err)
{
    (void)rng; /* deterministic: the fitted template's vertices */
    neupig_method *m = self;
    const tcb_uv_mesh none = {0, 0, 0, NULL, NULL, NULL, NULL};
    *out = none;
    int rc = steps_model(m, err);
    return rc ? rc : tcb_pcgrid_surface(&m->fitted, seq, frame, out, err);
}

/* ---- the model file: the parameters under a manifest of the architecture ---- */

static cJSON *manifest(const neupig_method *m, size_t n_params)
{
    const tcb_neupig_arch *a = &m->arch;
    cJSON *j = cJSON_CreateObject();
    cJSON_AddStringToObject(j, "method", "neupig");
    const int sizes[] = {a->levels, a->base_res, a->res_step, a->features, a->normal_res, a->normal_features,
                         a->time_freqs, a->hidden, m->points, m->template_faces, m->poisson_depth, m->gt_normals};
    const char *const names[] = {"levels", "base_res", "res_step", "features", "normal_res", "normal_features",
                                 "time_freqs", "hidden", "points", "template_faces", "poisson_depth", "gt_normals"};
    for (size_t k = 0; k < sizeof sizes / sizeof sizes[0]; k++) cJSON_AddNumberToObject(j, names[k], sizes[k]);
    cJSON_AddStringToObject(j, "laplacian", tcb_sobolev_laplacian_names[a->laplacian]);
    cJSON_AddNumberToObject(j, "parameters", (double)n_params);
    return j;
}

static size_t n_params_of(const neupig_method *m, tcb_error *err)
{
    tcb_neupig_model model;
    if (tcb_neupig_model_init(&model, &m->arch, err)) return 0;
    size_t n = model.n_params;
    tcb_neupig_model_free(&model);
    return n;
}

static int save(void *self, const char *path, tcb_error *err)
{
    neupig_method *m = self;
    if (!m->params) return tcb_fail(err, TCB_ERR_INTERNAL, "%s: neupig saved before fit", path);
    size_t n = n_params_of(m, err);
    if (!n) return err->code;
    cJSON *j = manifest(m, n);
    tcb_weight_parts w = {1, {m->params, NULL}, {n, 0}};
    int rc = tcb_model_file_write(path, MAGIC, m->seed, j, &w, err);
    cJSON_Delete(j);
    return rc;
}

static int load(void *self, const tcb_sequence *seq, const char *path, tcb_error *err)
{
    neupig_method *m = self;
    steps_free(m);
    release_model(m);
    size_t n = n_params_of(m, err);
    if (!n) return err->code;
    if (!(m->params = malloc(n * sizeof *m->params))) return tcb_fail(err, TCB_ERR_NOMEM, "neupig: out of memory");
    m->gt_normals = uses_gt_normals(m, seq);
    cJSON *want = manifest(m, n);
    tcb_weight_parts w = {1, {m->params, NULL}, {n, 0}};
    uint64_t seed = 0;
    int rc = tcb_model_file_read(path, MAGIC, want, &seed, &w, err);
    cJSON_Delete(want);
    inputs in;
    memset(&in, 0, sizeof in);
    if (!rc) rc = prepare(m, seq, seed, &in, err);
    if (!rc) rc = deform_all(m, &in, err);
    inputs_free(&in);
    if (rc) release_model(m);
    else m->seed = seed;
    return rc;
}

/* ---- calibration (tcbench calibrate, the dry run) ---- */

/* tcb_method_ops.train_steps: fit's training (its inputs and template
 * built by the first call) n epochs at a time; the fitted model follows
 * from the epochs done when a transfer, reconstruct or surface first asks
 * (steps_model), so that the timed calls are epochs only. */
struct steps {
    inputs in;
    fit_state s;
};

static void steps_free(neupig_method *m)
{
    if (!m->steps) return;
    tcb_neupig_trainer_free(&m->steps->s.trainer);
    inputs_free(&m->steps->in);
    free(m->steps);
    m->steps = NULL;
}

static int train_steps(void *self, const tcb_sequence *seq, const tcb_fit_ctx *ctx, long long n, tcb_error *err)
{
    neupig_method *m = self;
    int rc = TCB_OK;
    if (!m->steps) {
        release_model(m);
        m->seed = ctx->seed;
        if (!(m->steps = calloc(1, sizeof *m->steps))) return tcb_fail(err, TCB_ERR_NOMEM, "neupig: out of memory");
        m->steps->s.seed = ctx->seed;
        rc = prepare(m, seq, ctx->seed, &m->steps->in, err);
        if (!rc)
            rc = tcb_neupig_trainer_init(&m->steps->s.trainer, &m->arch, &m->sched, &m->steps->in.problem, ctx->seed,
                                         err);
        if (rc) steps_free(m);
    }
    double loss;
    for (long long k = 0; !rc && k < n; k++) rc = tcb_neupig_train_step(&m->steps->s.trainer, &loss, err);
    free(m->fitted.deformed), free(m->params);
    m->fitted.deformed = NULL, m->params = NULL; /* the model of fewer epochs */
    return rc;
}

/* The model of train_steps' epochs, once they stopped; nothing without. */
static int steps_model(neupig_method *m, tcb_error *err)
{
    if (!m->steps || m->fitted.deformed) return TCB_OK;
    const tcb_neupig_trainer *t = &m->steps->s.trainer;
    if (!(m->params = malloc(t->model.n_params * sizeof *m->params)))
        return tcb_fail(err, TCB_ERR_NOMEM, "neupig: out of memory");
    memcpy(m->params, t->params, t->model.n_params * sizeof *m->params);
    return deform_all(m, &m->steps->in, err);
}

/* tcb_method_ops.run_unit: "template", the inputs and template mesh a fit
 * (and a load) builds before its first epoch: the clouds, the keyframe,
 * its screened Poisson surface and the decimation. Built on a copy, so that
 * a training of train_steps keeps its own. */
static int run_unit(void *self, const tcb_sequence *seq, const tcb_fit_ctx *ctx, int unit, tcb_error *err)
{
    if (unit != UNIT_TEMPLATE) return tcb_fail(err, TCB_ERR_INTERNAL, "neupig: no unit %d", unit);
    neupig_method scratch = *(const neupig_method *)self;
    scratch.fitted.template_mesh = (tcb_mesh){0, 0, NULL, NULL};
    inputs in;
    int rc = prepare(&scratch, seq, ctx->seed, &in, err);
    inputs_free(&in);
    tcb_mesh_free(&scratch.fitted.template_mesh);
    return rc;
}

/* The calibrated preset of m's sizes; -1 when one differs from each. */
static int calibrated_preset(const neupig_method *m)
{
    for (int k = 0; calibrated_presets[k]; k++) {
        int pi = 0;
        while (strcmp(preset_names[pi], calibrated_presets[k])) pi++;
        const neupig_preset *p = &presets[pi];
        if (m->points == p->points && m->template_faces == p->template_faces &&
            m->poisson_depth == p->poisson_depth && m->arch.levels == p->levels && m->arch.features == p->features &&
            m->arch.hidden == p->hidden && m->recon_points == DEFAULT_RECON_POINTS)
            return k;
    }
    return -1;
}

/* A fit: its epochs (each over every frame: step_frames), after the
 * template, which a fit builds once (its Poisson surface at depth 10 is
 * seconds). */
static void estimate(void *self, const tcb_cost_query *q, tcb_cost_estimate *out)
{
    (void)q;
    const neupig_method *m = self;
    int k = calibrated_preset(m);
    tcb_step_cost_estimate("neupig", calibrated_presets, k, m->sched.epochs, out);
    out->step_frames = 1;
    if (k >= 0) out->units[out->n_units++] = (tcb_unit_use){"template", 1, 0, 0, 0};
}

const tcb_method_ops tcb_method_neupig = {
    .abi_version = TCB_METHOD_ABI_VERSION,
    .name = "neupig",
    .description = "Neu-PiG (CVPR 2026): a Poisson template of the keyframe moved per vertex by an MLP "
                   "on preconditioned feature grids and time; barycentric read-out",
    .create = create,
    .fit = fit,
    .transfer = transfer,
    .reconstruct = reconstruct,
    .save = save,
    .load = load,
    .destroy = destroy,
    .estimate = estimate,
    .surface = surface,
    .presets = calibrated_presets,
    .train_steps = train_steps,
    .units = unit_names,
    .run_unit = run_unit,
    .normals = normals_used,
};
