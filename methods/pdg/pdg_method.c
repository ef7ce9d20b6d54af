/* pdg: Preconditioned Deformation Grids (PDG, Computer Graphics Forum
 * 2025): one template, the keyframe's screened Poisson surface remeshed
 * and decimated (methods/pcgrid/template.h), carried outward from the
 * keyframe through one translation field per frame transition, each a
 * mean of preconditioned lattice levels (methods/pdg/field.h), the
 * template itself evolving under Large Steps; optimised per sequence on
 * the frames' point clouds (methods/pdg/train.h). docs/protocol.md, "PDG",
 * lists the reference files followed and every difference.
 *
 * Params (presets overridable key by key; default cpu):
 *   preset        paper (5 000 epochs, 5 000 points a frame, 10 levels,
 *                 depth 10), cpu (sizes for 2 cores: docs/protocol.md,
 *                 "PDG"), tiny (tests)
 *   normals       input (default) | estimated | gt: the keyframe's normals
 *                 for the Poisson surface, as neupig's
 *   keyframe_res  the keyframe rule's lattice (128, the release's default;
 *                 its AMA script passes 512)
 *   epochs, warmup, points, template_faces (default min(20 000, 4·points)),
 *   poisson_depth, levels, recon_points, checkpoint_every, divergence
 *
 * Read-out and checkpoints as neupig's (methods/pcgrid/fitted.h): the
 * model file holds every parameter — the fields' and the template's
 * Large-Steps u — and load rebuilds the starting template (its faces and
 * Laplacian) from the sequence with the fit's seed. */
#include <stdlib.h>
#include <string.h>

#include "methods/builtin.h"
#include "methods/params.h"
#include "methods/pcgrid/fitted.h"
#include "methods/pcgrid/template.h"
#include "methods/pdg/train.h"
#include "methods/step_cost.h"
#include "neural/train_loop.h"
#include "neural/weights.h"
#include "tcb/json.h"
#include "tcb/meshing.h"

#define CKPT_NAME "train.ckpt"
#define MAGIC "TCBPDG01"
#define DEFAULT_RECON_POINTS 2500
#define TEMPLATE_CHECK_SAMPLES 100000 /* the release's PyTorch3D Chamfer on 100 000 samples a mesh */
#define TEMPLATE_CHECK_CHAMFER 5e-4
#define TEMPLATE_ROUNDS 10
#define TEMPLATE_REMESH_ITERATIONS 5

typedef struct pdg_preset {
    long long epochs, warmup;
    int points, poisson_depth, levels;
} pdg_preset;

static const pdg_preset presets[] = {
    {5000, 101, 5000, 10, 10}, /* paper */
    {1000, 101, 2500, 8, 10},  /* cpu */
    {40, 10, 300, 6, 3},       /* tiny: the chains train too */
};
static const char *const preset_names[] = {"paper", "cpu", "tiny", NULL};
static const char *const normals_names[] = {"estimated", "gt", "input", NULL};
enum { NORMALS_ESTIMATED, NORMALS_GT, NORMALS_INPUT };
static const char *const calibrated_presets[] = {"paper", "cpu", "tiny", NULL};
static const char *const unit_names[] = {"template", NULL};
enum { UNIT_TEMPLATE };

struct steps;

typedef struct pdg_method {
    tcb_pdg_arch arch;
    tcb_pdg_schedule sched;
    int points, template_faces, poisson_depth, keyframe_res, recon_points;
    int normals, gt_normals;
    long long checkpoint_every;
    uint64_t seed;
    float *params;                 /* the fitted parameters (after fit or load) */
    size_t n_params;
    tcb_pcgrid_fitted fitted;
    struct steps *steps;           /* train_steps' training; NULL: none */
} pdg_method;

static int parse(const char *params_json, void *obj, tcb_error *err)
{
    pdg_method *m = obj;
    static const char *const keys[] = {"preset",         "normals",     "keyframe_res", "epochs",
                                       "warmup",         "points",      "template_faces", "poisson_depth",
                                       "levels",         "recon_points", "checkpoint_every", "divergence", NULL};
    const char *where = "pdg.params";
    cJSON *j;
    int rc = tcb_params_parse(params_json, where, keys, &j, err);
    if (rc) return rc;
    int pi = 1, ni = NORMALS_INPUT;
    long long epochs, warmup, points, faces, depth, levels, recon, kres;
    rc = tcb_json_enum(j, "preset", where, 0, 1, preset_names, &pi, err);
    if (!rc) rc = tcb_json_enum(j, "normals", where, 0, NORMALS_INPUT, normals_names, &ni, err);
    const pdg_preset *p = &presets[pi];
    if (!rc) rc = tcb_json_int(j, "epochs", where, 0, p->epochs, 1, 100000000, &epochs, err);
    if (!rc) rc = tcb_json_int(j, "warmup", where, 0, p->warmup, 0, 100000000, &warmup, err);
    if (!rc) rc = tcb_json_int(j, "points", where, 0, p->points, 4, 10000000, &points, err);
    long long budget = 4 * (!rc ? points : 0) < 20000 ? 4 * points : 20000;
    if (!rc) rc = tcb_json_int(j, "template_faces", where, 0, budget, 4, 10000000, &faces, err);
    if (!rc) rc = tcb_json_int(j, "poisson_depth", where, 0, p->poisson_depth, TCB_POISSON_DEPTH_MIN,
                                TCB_POISSON_DEPTH_MAX, &depth, err);
    if (!rc) rc = tcb_json_int(j, "levels", where, 0, p->levels, 1, TCB_PDG_MAX_LEVELS, &levels, err);
    if (!rc) rc = tcb_json_int(j, "keyframe_res", where, 0, 128, 1, 4096, &kres, err);
    if (!rc) rc = tcb_json_int(j, "recon_points", where, 0, DEFAULT_RECON_POINTS, 1, 10000000, &recon, err);
    if (!rc) rc = tcb_json_int(j, "checkpoint_every", where, 0, 50, 0, 100000000, &m->checkpoint_every, err);
    if (!rc) rc = tcb_json_num(j, "divergence", where, 0, 1e4, 0, 1e300, &m->sched.divergence, err);
    cJSON_Delete(j);
    if (rc) return rc;
    m->arch = tcb_pdg_arch_reference();
    m->arch.levels = (int)levels;
    m->sched.epochs = epochs, m->sched.warmup = warmup;
    m->sched.lr_grid = 0.005, m->sched.lr_growth = 1.1, m->sched.lr_template = 1e-4;
    m->points = (int)points, m->template_faces = (int)faces, m->poisson_depth = (int)depth;
    m->keyframe_res = (int)kres, m->recon_points = (int)recon, m->normals = ni;
    m->fitted.method = "pdg";
    return TCB_OK;
}

static void release_model(pdg_method *m)
{
    free(m->params);
    m->params = NULL, m->n_params = 0;
    tcb_pcgrid_fitted_release(&m->fitted);
}

static int create(const char *params_json, void **self, tcb_error *err)
{
    return tcb_method_create(sizeof(pdg_method), "pdg", params_json, parse, NULL, self, err);
}

static void steps_free(pdg_method *m);

static void destroy(void *self)
{
    pdg_method *m = self;
    if (!m) return;
    steps_free(m);
    release_model(m);
    free(m);
}

/* ---- the inputs of an optimisation, rebuilt identically by fit and load ---- */

typedef struct inputs {
    tcb_pcgrid_clouds c;
    tcb_pdg_data data;
} inputs;

static void inputs_free(inputs *in)
{
    tcb_pcgrid_clouds_free(&in->c);
    memset(in, 0, sizeof *in);
}

static int uses_gt_normals(const pdg_method *m, const tcb_sequence *seq)
{
    return m->normals == NORMALS_GT || (m->normals == NORMALS_INPUT && seq->input_normals == TCB_INPUT_NORMALS_GT);
}

static const char *normals_used(void *self, const tcb_sequence *seq)
{
    return uses_gt_normals(self, seq) ? "gt" : "estimated";
}

/* The clouds (stream (seed, "pdg/points")), the keyframe, the template. */
static int prepare(pdg_method *m, const tcb_sequence *seq, uint64_t seed, inputs *in, tcb_error *err)
{
    memset(in, 0, sizeof *in);
    tcb_mesh_free(&m->fitted.template_mesh);
    m->gt_normals = uses_gt_normals(m, seq);
    int key = 0;
    int rc = tcb_pcgrid_clouds_draw(seq, m->points, seed, "pdg/points", &m->fitted.map, &in->c, err);
    if (!rc) rc = tcb_pcgrid_keyframe((const float *const *)in->c.clouds, in->c.n, in->c.T, m->keyframe_res, &key, err);
    const tcb_pcgrid_template_spec spec = {.gt_normals = m->gt_normals,
                                           .poisson_depth = m->poisson_depth,
                                           .template_faces = m->template_faces,
                                           .remesh_iterations = TEMPLATE_REMESH_ITERATIONS,
                                           .check_samples = TEMPLATE_CHECK_SAMPLES,
                                           .max_rounds = TEMPLATE_ROUNDS,
                                           .check_chamfer = TEMPLATE_CHECK_CHAMFER,
                                           .seed = seed};
    if (!rc)
        rc = tcb_pcgrid_template_build(seq, key, &m->fitted.map, in->c.clouds[key], in->c.n[key], &spec,
                                       &m->fitted.template_mesh, err);
    if (!rc && in->c.T < 2)
        rc = tcb_fail(err, TCB_ERR_INPUT, "a sequence of %d frame has no transition to fit", in->c.T);
    if (!rc)
        in->data = (tcb_pdg_data){in->c.T, key, (const float *const *)in->c.clouds, in->c.n,
                                  (const tcb_nn *const *)in->c.index, &m->fitted.template_mesh};
    if (rc) tcb_error_prefix(err, "pdg: ");
    return rc;
}

/* The fitted frames of the trainer's parameters, kept with a copy of them. */
static int keep_model(pdg_method *m, tcb_pdg_trainer *t, tcb_error *err)
{
    free(m->params), free(m->fitted.deformed);
    m->fitted.n_frames = t->data->n;
    m->n_params = t->n_params;
    m->params = malloc(t->n_params * sizeof *m->params);
    m->fitted.deformed = malloc((size_t)t->data->n * (size_t)m->fitted.template_mesh.n_verts * 3 * sizeof(float));
    if (!m->params || !m->fitted.deformed) return tcb_fail(err, TCB_ERR_NOMEM, "pdg: out of memory");
    memcpy(m->params, t->params, t->n_params * sizeof *m->params);
    return tcb_pdg_trainer_frames(t, m->fitted.deformed, err);
}

/* ---- fit ---- */

static int fit_step(void *t, double *loss, tcb_error *err) { return tcb_pdg_train_step(t, loss, err); }
static long long fit_done(const void *t) { return ((const tcb_pdg_trainer *)t)->it; }

typedef struct fit_state {
    tcb_pdg_trainer trainer;
    uint64_t seed;
} fit_state;

static int fit_save(const void *f, double seconds, const char *path, tcb_error *err)
{
    const fit_state *s = f;
    return tcb_pdg_train_save(&s->trainer, s->seed, seconds, path, err);
}

static int fit_load(void *f, const char *path, double *seconds, tcb_error *err)
{
    fit_state *s = f;
    return tcb_pdg_train_load(&s->trainer, s->seed, path, seconds, err);
}

static int fit(void *self, const tcb_sequence *seq, const tcb_fit_ctx *ctx, tcb_error *err)
{
    pdg_method *m = self;
    steps_free(m);
    release_model(m);
    m->seed = ctx->seed;
    inputs in;
    fit_state s = {.seed = ctx->seed};
    int rc = prepare(m, seq, ctx->seed, &in, err);
    if (!rc) rc = tcb_pcgrid_template_write(&m->fitted.template_mesh, &m->fitted.map, ctx->work_dir, in.data.key, err);
    if (!rc) rc = tcb_pdg_trainer_init(&s.trainer, &m->arch, &m->sched, &in.data, err);
    if (!rc) {
        tcb_train_loop loop = {.name = "pdg", .iterations = m->sched.epochs, .checkpoint_every = m->checkpoint_every,
                               .ckpt_name = CKPT_NAME, .trainer = &s, .step = fit_step, .done = fit_done,
                               .save = fit_save, .load = fit_load};
        rc = tcb_train_loop_run(&loop, ctx, err);
    }
    if (!rc) rc = keep_model(m, &s.trainer, err);
    tcb_pdg_trainer_free(&s.trainer);
    inputs_free(&in);
    return rc;
}

/* ---- read-out ---- */

static int steps_model(pdg_method *m, tcb_error *err);

static int transfer(void *self, const tcb_sequence *seq, int i, int j, const float *src, int n, float *out,
                    tcb_rng *rng, tcb_error *err)
{
    (void)rng;
    pdg_method *m = self;
    int rc = steps_model(m, err);
    return rc ? rc : tcb_pcgrid_transfer(&m->fitted, seq, i, j, src, n, out, err);
}

static int reconstruct(void *self, const tcb_sequence *seq, int i, int j, int frame, tcb_rng *rng, float **pts,
                       int *n, tcb_error *err)
{
    pdg_method *m = self;
    *pts = NULL;
    int rc = steps_model(m, err);
    return rc ? rc : tcb_pcgrid_reconstruct(&m->fitted, seq, i, j, frame, m->recon_points, rng, pts, n, err);
}

/* The template carried to `frame`, in the sequence's coordinates, without
 * charts; the same faces in every frame. */
static int surface(void *self, const tcb_sequence *seq, int frame, tcb_rng *rng, tcb_uv_mesh *out, tcb_error *err)
{
    (void)rng;
    pdg_method *m = self;
    const tcb_uv_mesh none = {0, 0, 0, NULL, NULL, NULL, NULL};
    *out = none;
    int rc = steps_model(m, err);
    return rc ? rc : tcb_pcgrid_surface(&m->fitted, seq, frame, out, err);
}

/* ---- the model file: the parameters under a manifest ---- */

static cJSON *manifest(const pdg_method *m, size_t n_params)
{
    cJSON *j = cJSON_CreateObject();
    cJSON_AddStringToObject(j, "method", "pdg");
    const int sizes[] = {m->arch.levels, m->points, m->template_faces, m->poisson_depth, m->keyframe_res,
                         m->gt_normals};
    const char *const names[] = {"levels", "points", "template_faces", "poisson_depth", "keyframe_res",
                                 "gt_normals"};
    for (size_t k = 0; k < sizeof sizes / sizeof sizes[0]; k++) cJSON_AddNumberToObject(j, names[k], sizes[k]);
    cJSON_AddNumberToObject(j, "parameters", (double)n_params);
    return j;
}

static int save(void *self, const char *path, tcb_error *err)
{
    pdg_method *m = self;
    if (!m->params) return tcb_fail(err, TCB_ERR_INTERNAL, "%s: pdg saved before fit", path);
    cJSON *j = manifest(m, m->n_params);
    tcb_weight_parts w = {1, {m->params, NULL}, {m->n_params, 0}};
    int rc = tcb_model_file_write(path, MAGIC, m->seed, j, &w, err);
    cJSON_Delete(j);
    return rc;
}

static int load(void *self, const tcb_sequence *seq, const char *path, tcb_error *err)
{
    pdg_method *m = self;
    steps_free(m);
    release_model(m);
    inputs in;
    tcb_pdg_trainer t;
    memset(&t, 0, sizeof t);
    uint64_t seed = 0;
    /* the parameters' count comes with the template, which the seed in the file rebuilds */
    int rc = tcb_model_file_seed(path, MAGIC, &seed, err);
    if (!rc) rc = prepare(m, seq, seed, &in, err);
    if (!rc) rc = tcb_pdg_trainer_init(&t, &m->arch, &m->sched, &in.data, err);
    if (!rc) {
        cJSON *want = manifest(m, t.n_params);
        tcb_weight_parts w = {1, {t.params, NULL}, {t.n_params, 0}};
        rc = tcb_model_file_read(path, MAGIC, want, &seed, &w, err);
        cJSON_Delete(want);
    }
    if (!rc) rc = keep_model(m, &t, err);
    tcb_pdg_trainer_free(&t);
    inputs_free(&in);
    if (rc) release_model(m);
    else m->seed = seed;
    return rc;
}

/* ---- calibration (tcbench calibrate, the dry run) ---- */

/* tcb_method_ops.train_steps: fit's training n epochs at a time; the model
 * follows from the epochs done when a read-out first asks (steps_model). */
struct steps {
    inputs in;
    fit_state s;
};

static void steps_free(pdg_method *m)
{
    if (!m->steps) return;
    tcb_pdg_trainer_free(&m->steps->s.trainer);
    inputs_free(&m->steps->in);
    free(m->steps);
    m->steps = NULL;
}

static int train_steps(void *self, const tcb_sequence *seq, const tcb_fit_ctx *ctx, long long n, tcb_error *err)
{
    pdg_method *m = self;
    int rc = TCB_OK;
    if (!m->steps) {
        release_model(m);
        m->seed = ctx->seed;
        if (!(m->steps = calloc(1, sizeof *m->steps))) return tcb_fail(err, TCB_ERR_NOMEM, "pdg: out of memory");
        m->steps->s.seed = ctx->seed;
        rc = prepare(m, seq, ctx->seed, &m->steps->in, err);
        if (!rc) rc = tcb_pdg_trainer_init(&m->steps->s.trainer, &m->arch, &m->sched, &m->steps->in.data, err);
        if (rc) steps_free(m);
    }
    double loss;
    for (long long k = 0; !rc && k < n; k++) rc = tcb_pdg_train_step(&m->steps->s.trainer, &loss, err);
    free(m->fitted.deformed), free(m->params);
    m->fitted.deformed = NULL, m->params = NULL; /* the model of fewer epochs */
    return rc;
}

static int steps_model(pdg_method *m, tcb_error *err)
{
    if (!m->steps || m->fitted.deformed) return TCB_OK;
    return keep_model(m, &m->steps->s.trainer, err);
}

/* tcb_method_ops.run_unit: "template", the inputs and template a fit (and a
 * load) builds before its first epoch. Built on a copy, so that a training
 * of train_steps keeps its own. */
static int run_unit(void *self, const tcb_sequence *seq, const tcb_fit_ctx *ctx, int unit, tcb_error *err)
{
    if (unit != UNIT_TEMPLATE) return tcb_fail(err, TCB_ERR_INTERNAL, "pdg: no unit %d", unit);
    pdg_method scratch = *(const pdg_method *)self;
    scratch.fitted.template_mesh = (tcb_mesh){0, 0, NULL, NULL};
    inputs in;
    int rc = prepare(&scratch, seq, ctx->seed, &in, err);
    inputs_free(&in);
    tcb_mesh_free(&scratch.fitted.template_mesh);
    return rc;
}

/* The calibrated preset of m's sizes; -1 when one differs from each. */
static int calibrated_preset(const pdg_method *m)
{
    for (int k = 0; calibrated_presets[k]; k++) {
        const pdg_preset *p = &presets[k];
        int faces = 4 * p->points < 20000 ? 4 * p->points : 20000;
        if (m->points == p->points && m->template_faces == faces && m->poisson_depth == p->poisson_depth &&
            m->arch.levels == p->levels && m->recon_points == DEFAULT_RECON_POINTS)
            return k;
    }
    return -1;
}

/* A fit: its epochs (each over every frame: step_frames), after the
 * template, which a fit builds once. */
static void estimate(void *self, const tcb_cost_query *q, tcb_cost_estimate *out)
{
    (void)q;
    const pdg_method *m = self;
    int k = calibrated_preset(m);
    tcb_step_cost_estimate("pdg", calibrated_presets, k, m->sched.epochs, out);
    out->step_frames = 1;
    if (k >= 0) out->units[out->n_units++] = (tcb_unit_use){"template", 1, 0, 0, 0};
}

const tcb_method_ops tcb_method_pdg = {
    .abi_version = TCB_METHOD_ABI_VERSION,
    .name = "pdg",
    .description = "PDG (CGF 2025): a remeshed Poisson template of the keyframe carried frame to frame by "
                   "preconditioned translation grids, the template evolving under Large Steps; barycentric read-out",
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
