/* pdg: Preconditioned Deformation Grids (PDG, Computer Graphics Forum
 * 2025): one template, the keyframe's screened Poisson surface remeshed
 * and decimated (methods/pcgrid/template.h), carried outward from the
 * keyframe through one deformation field per frame transition, each a
 * mean of preconditioned lattice levels (methods/pdg/field.h), the
 * template itself evolving under Large Steps; optimised per sequence on
 * the frames' point clouds (methods/pdg/train.h). docs/protocol.md, "PDG",
 * lists the reference files followed and every difference.
 *
 * Params (presets overridable key by key; default cpu):
 *   preset        paper (5 000 epochs, 5 000 points a frame, 10 levels,
 *                 depth 10), cpu (sizes for 2 cores: docs/protocol.md,
 *                 "PDG"), tiny (tests); paper-cayley and cpu-cayley are
 *                 paper and cpu with the cayley rotation, presets so that
 *                 calibrate measures their dearer epochs
 *   normals       input (default) | estimated | gt: the keyframe's normals
 *                 for the Poisson surface, as neupig's
 *   keyframe_res  the keyframe rule's lattice (128, the release's default;
 *                 its AMA script passes 512)
 *   rotation      released (default): translations alone, as the release
 *                 deforms (its rotation never leaves the identity), 3
 *                 values a node | cayley: the proper Cayley rotation
 *                 composed as the release composes its transforms, 6
 *                 values a node (methods/pdg/field.h); the model file and
 *                 the checkpoints of one are refused by the other
 *   epochs, warmup, points, template_faces (default min(20 000, 4·points)),
 *   poisson_depth, levels, recon_points, checkpoint_every, divergence
 *
 * Read-out, checkpoints, the model file and the calibration are the pcgrid
 * methods' shared ops (methods/pcgrid/method.h); this file holds the
 * params, the trainer's hooks and the estimate. The model file holds every
 * parameter — the fields' and the template's Large-Steps u — and load
 * rebuilds the starting template (its faces and Laplacian) from the
 * sequence with the fit's seed. */
#include <stdlib.h>
#include <string.h>

#include "methods/builtin.h"
#include "methods/params.h"
#include "methods/pcgrid/method.h"
#include "methods/pdg/train.h"
#include "tcb/json.h"
#include "tcb/meshing.h"

#define TEMPLATE_CHECK_SAMPLES 100000 /* the release's PyTorch3D Chamfer on 100 000 samples a mesh */
#define TEMPLATE_CHECK_CHAMFER 5e-4
#define TEMPLATE_ROUNDS 10
#define TEMPLATE_REMESH_ITERATIONS 5

typedef struct pdg_preset {
    long long epochs, warmup;
    int points, poisson_depth, levels;
    tcb_pdg_rotation rotation;
} pdg_preset;

static const pdg_preset presets[] = {
    {5000, 101, 5000, 10, 10, TCB_PDG_RELEASED}, /* paper */
    {2000, 101, 2500, 8, 10, TCB_PDG_RELEASED},  /* cpu: about 12 min a crane clip, 22 min the cat (docs/protocol.md) */
    {40, 10, 300, 6, 3, TCB_PDG_RELEASED},       /* tiny: the chains train too */
    {5000, 101, 5000, 10, 10, TCB_PDG_CAYLEY},   /* paper-cayley */
    {2000, 101, 2500, 8, 10, TCB_PDG_CAYLEY},    /* cpu-cayley */
};
static const char *const preset_names[] = {"paper", "cpu", "tiny", "paper-cayley", "cpu-cayley", NULL};

typedef struct pdg_method {
    tcb_pcgrid_method base;        /* first: the shared ops take the object as it */
    tcb_pdg_arch arch;
    tcb_pdg_schedule sched;
} pdg_method;

static const tcb_pcgrid_hooks hooks;

/* The release's triangle budget: min(20 000, 4 · points). */
static long long template_budget(long long points) { return 4 * points < 20000 ? 4 * points : 20000; }

static int parse(const char *params_json, void *obj, tcb_error *err)
{
    pdg_method *m = obj;
    tcb_pcgrid_method *b = &m->base;
    static const char *const keys[] = {"preset",         "normals",     "keyframe_res", "epochs",
                                       "warmup",         "points",      "template_faces", "poisson_depth",
                                       "levels",         "recon_points", "checkpoint_every", "divergence",
                                       "rotation",       NULL};
    const char *where = "pdg.params";
    cJSON *j;
    int rc = tcb_params_parse(params_json, where, keys, &j, err);
    if (rc) return rc;
    int pi = 1, rotation;
    long long epochs, warmup, points = 0, faces, depth, levels, kres;
    rc = tcb_json_enum(j, "preset", where, 0, 1, preset_names, &pi, err);
    if (!rc) rc = tcb_pcgrid_parse_common(j, where, b, err);
    const pdg_preset *p = &presets[pi];
    if (!rc) rc = tcb_json_int(j, "epochs", where, 0, p->epochs, 1, 100000000, &epochs, err);
    if (!rc) rc = tcb_json_int(j, "warmup", where, 0, p->warmup, 0, 100000000, &warmup, err);
    if (!rc) rc = tcb_json_int(j, "points", where, 0, p->points, 4, 10000000, &points, err);
    if (!rc) rc = tcb_json_int(j, "template_faces", where, 0, template_budget(points), 4, 10000000, &faces, err);
    if (!rc) rc = tcb_json_int(j, "poisson_depth", where, 0, p->poisson_depth, TCB_POISSON_DEPTH_MIN,
                                TCB_POISSON_DEPTH_MAX, &depth, err);
    if (!rc) rc = tcb_json_int(j, "levels", where, 0, p->levels, 1, TCB_PDG_MAX_LEVELS, &levels, err);
    if (!rc) rc = tcb_json_int(j, "keyframe_res", where, 0, 128, 1, 4096, &kres, err);
    if (!rc) rc = tcb_json_num(j, "divergence", where, 0, 1e4, 0, 1e300, &m->sched.divergence, err);
    if (!rc) rc = tcb_json_enum(j, "rotation", where, 0, p->rotation, tcb_pdg_rotation_names, &rotation, err);
    cJSON_Delete(j);
    if (rc) return rc;
    m->arch = tcb_pdg_arch_reference();
    m->arch.levels = (int)levels;
    m->arch.rotation = (tcb_pdg_rotation)rotation;
    m->sched.epochs = epochs, m->sched.warmup = warmup;
    m->sched.lr_grid = 0.005, m->sched.lr_growth = 1.1, m->sched.lr_template = 1e-4;
    b->hooks = &hooks, b->fitted.method = hooks.name;
    b->epochs = epochs, b->points = (int)points, b->keyframe_res = (int)kres;
    b->spec = (tcb_pcgrid_template_spec){.poisson_depth = (int)depth,
                                         .template_faces = (int)faces,
                                         .remesh_iterations = TEMPLATE_REMESH_ITERATIONS,
                                         .check_samples = TEMPLATE_CHECK_SAMPLES,
                                         .max_rounds = TEMPLATE_ROUNDS,
                                         .check_chamfer = TEMPLATE_CHECK_CHAMFER};
    return TCB_OK;
}

static int create(const char *params_json, void **self, tcb_error *err)
{
    return tcb_method_create(sizeof(pdg_method), "pdg", params_json, parse, NULL, self, err);
}

/* ---- the trainer's hooks (methods/pcgrid/method.h) ---- */

static int problem_init(void *self, const tcb_sequence *seq, tcb_pcgrid_inputs *in, tcb_error *err)
{
    (void)self, (void)seq;
    const tcb_pcgrid_clouds *c = &in->clouds;
    if (c->T < 2) return tcb_fail(err, TCB_ERR_INPUT, "a sequence of %d frame has no transition to fit", c->T);
    *(tcb_pdg_data *)in->problem = (tcb_pdg_data){c->T, in->key, (const float *const *)c->clouds, c->n,
                                                  (const tcb_nn *const *)c->index, in->template_mesh};
    return TCB_OK;
}

static void problem_free(void *problem) { (void)problem; /* views of the inputs */ }

static int trainer_init(void *t, const void *self, const void *data, uint64_t seed, tcb_error *err)
{
    (void)seed; /* the fields start at zero, the template as built */
    const pdg_method *m = self;
    return tcb_pdg_trainer_init(t, &m->arch, &m->sched, data, err);
}

static void trainer_free(void *t) { tcb_pdg_trainer_free(t); }
static int step(void *t, double *loss, tcb_error *err) { return tcb_pdg_train_step(t, loss, err); }
static long long done(const void *t) { return ((const tcb_pdg_trainer *)t)->it; }

static int save(const void *t, uint64_t seed, double seconds, const char *path, tcb_error *err)
{
    return tcb_pdg_train_save(t, seed, seconds, path, err);
}

static int load(void *t, uint64_t seed, const char *path, double *seconds, tcb_error *err)
{
    return tcb_pdg_train_load(t, seed, path, seconds, err);
}

static float *params(void *t_, size_t *n)
{
    tcb_pdg_trainer *t = t_;
    *n = t->n_params;
    return t->params;
}

static int frames(void *t, float *X, tcb_error *err) { return tcb_pdg_trainer_frames(t, X, err); }

/* Every term from the first epoch: an epoch's cost does not depend on its
 * number, only on whether it is a warm-up one. */
static void main_phase(void *t) { ((tcb_pdg_trainer *)t)->sched.warmup = 0; }

static cJSON *manifest(const void *self, size_t n_params)
{
    const pdg_method *m = self;
    const tcb_pcgrid_method *b = &m->base;
    cJSON *j = cJSON_CreateObject();
    cJSON_AddStringToObject(j, "method", "pdg");
    const int sizes[] = {m->arch.levels, b->points, b->spec.template_faces, b->spec.poisson_depth, b->keyframe_res,
                         b->spec.gt_normals};
    const char *const names[] = {"levels", "points", "template_faces", "poisson_depth", "keyframe_res",
                                 "gt_normals"};
    for (size_t k = 0; k < sizeof sizes / sizeof sizes[0]; k++) cJSON_AddNumberToObject(j, names[k], sizes[k]);
    cJSON_AddStringToObject(j, "rotation", tcb_pdg_rotation_names[m->arch.rotation]);
    cJSON_AddNumberToObject(j, "parameters", (double)n_params);
    return j;
}

static const tcb_pcgrid_hooks hooks = {
    .name = "pdg", .magic = "TCBPDG01",
    .problem_size = sizeof(tcb_pdg_data), .trainer_size = sizeof(tcb_pdg_trainer),
    .problem_init = problem_init, .problem_free = problem_free,
    .trainer_init = trainer_init, .trainer_free = trainer_free,
    .step = step, .done = done, .save = save, .load = load,
    .params = params, .frames = frames, .manifest = manifest, .main_phase = main_phase,
};

/* ---- the dry run's estimate ---- */

/* The calibrated preset of m's sizes and rotation (every preset is
 * calibrated; the cayley rotation's twice the values a node make its
 * epochs dearer, hence its presets); -1 when one differs from each. */
static int calibrated_preset(const pdg_method *m)
{
    const tcb_pcgrid_method *b = &m->base;
    for (int k = 0; preset_names[k]; k++) {
        const pdg_preset *p = &presets[k];
        if (b->points == p->points && b->spec.template_faces == template_budget(p->points) &&
            b->spec.poisson_depth == p->poisson_depth && m->arch.levels == p->levels &&
            b->recon_points == TCB_PCGRID_RECON_POINTS && m->arch.rotation == p->rotation)
            return k;
    }
    return -1;
}

static void estimate(void *self, const tcb_cost_query *q, tcb_cost_estimate *out)
{
    (void)q;
    tcb_pcgrid_estimate(self, preset_names, calibrated_preset(self), out);
}

const tcb_method_ops tcb_method_pdg = {
    .abi_version = TCB_METHOD_ABI_VERSION,
    .name = "pdg",
    .description = "PDG (CGF 2025): a remeshed Poisson template of the keyframe carried frame to frame by "
                   "preconditioned translation grids (or translation and Cayley rotation), the template evolving "
                   "under Large Steps; barycentric read-out",
    .create = create,
    .estimate = estimate,
    .presets = preset_names,
    TCB_PCGRID_SHARED_OPS,
};
