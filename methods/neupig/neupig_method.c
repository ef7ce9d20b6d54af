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
 * deterministic) rather than storing it. All of this, the read-out and the
 * calibration are the pcgrid methods' shared ops (methods/pcgrid/method.h):
 * this file holds the params, the trainer's hooks and the estimate. */
#include <stdlib.h>
#include <string.h>

#include "methods/builtin.h"
#include "methods/neupig/train.h"
#include "methods/params.h"
#include "methods/pcgrid/method.h"
#include "tcb/json.h"
#include "tcb/meshing.h"

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
/* The presets `tcbench calibrate` measures: fast has paper's sizes (its
 * epochs cost what paper's do), so paper's step prices it. */
static const char *const calibrated_presets[] = {"paper", "cpu", "tiny", NULL};

typedef struct neupig_method {
    tcb_pcgrid_method base;        /* first: the shared ops take the object as it */
    tcb_neupig_arch arch;
    tcb_neupig_schedule sched;
} neupig_method;

static const tcb_pcgrid_hooks hooks;

static int parse(const char *params_json, void *obj, tcb_error *err)
{
    neupig_method *m = obj;
    tcb_pcgrid_method *b = &m->base;
    static const char *const keys[] = {"preset", "normals", "epochs", "points", "template_faces", "poisson_depth",
                                       "levels", "features", "hidden", "recon_points", "checkpoint_every",
                                       "divergence", "laplacian", NULL};
    const char *where = "neupig.params";
    cJSON *j;
    int rc = tcb_params_parse(params_json, where, keys, &j, err);
    if (rc) return rc;
    int pi = 2, li = TCB_SOBOLEV_PCGRID;
    long long epochs, points, faces, depth, levels, features, hidden;
    rc = tcb_json_enum(j, "preset", where, 0, 2, preset_names, &pi, err);
    if (!rc) rc = tcb_pcgrid_parse_common(j, where, b, err);
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
    if (!rc) rc = tcb_json_num(j, "divergence", where, 0, 1e4, 0, 1e300, &m->sched.divergence, err);
    cJSON_Delete(j);
    if (rc) return rc;
    m->arch = tcb_neupig_arch_reference();
    m->arch.levels = (int)levels, m->arch.features = (int)features, m->arch.hidden = (int)hidden;
    m->arch.laplacian = (tcb_sobolev_laplacian)li;
    m->sched.epochs = epochs, m->sched.lr_grid = 0.005, m->sched.lr_growth = 2.5, m->sched.lr_mlp = 1e-3;
    b->hooks = &hooks, b->fitted.method = hooks.name;
    b->epochs = epochs, b->points = (int)points, b->keyframe_res = TCB_PCGRID_KEYFRAME_RES;
    b->spec = (tcb_pcgrid_template_spec){.poisson_depth = (int)depth, .template_faces = (int)faces};
    return TCB_OK;
}

static int create(const char *params_json, void **self, tcb_error *err)
{
    return tcb_method_create(sizeof(neupig_method), "neupig", params_json, parse, NULL, self, err);
}

/* ---- the trainer's hooks (methods/pcgrid/method.h) ---- */

/* The problem: the template's vertex normals and edges beside the inputs. */
typedef struct problem {
    float *vnormals;     /* [nv][3] */
    int32_t *edges;      /* [ne][2] */
    float *edge_len;     /* [ne] */
    tcb_neupig_problem p;
} problem;

static int problem_init(void *self, const tcb_sequence *seq, tcb_pcgrid_inputs *in, tcb_error *err)
{
    (void)self, (void)seq;
    problem *pb = in->problem;
    const tcb_mesh *t = in->template_mesh;
    int ne = 0;
    int rc = tcb_pcgrid_template_normals(t, &pb->vnormals, err);
    if (!rc) rc = tcb_pcgrid_template_edges(t, &pb->edges, &pb->edge_len, &ne, err);
    const tcb_pcgrid_clouds *c = &in->clouds;
    if (!rc)
        pb->p = (tcb_neupig_problem){t->n_verts, t->verts, pb->vnormals, ne, pb->edges, pb->edge_len,
                                     c->T, (const float *const *)c->clouds, c->n,
                                     (const tcb_nn *const *)c->index, in->key};
    return rc;
}

static void problem_free(void *problem_)
{
    problem *pb = problem_;
    free(pb->vnormals), free(pb->edges), free(pb->edge_len);
}

static int trainer_init(void *t, const void *self, const void *pb, uint64_t seed, tcb_error *err)
{
    const neupig_method *m = self;
    return tcb_neupig_trainer_init(t, &m->arch, &m->sched, &((const problem *)pb)->p, seed, err);
}

static void trainer_free(void *t) { tcb_neupig_trainer_free(t); }
static int step(void *t, double *loss, tcb_error *err) { return tcb_neupig_train_step(t, loss, err); }
static long long done(const void *t) { return ((const tcb_neupig_trainer *)t)->it; }

static int save(const void *t, uint64_t seed, double seconds, const char *path, tcb_error *err)
{
    return tcb_neupig_train_save(t, seed, seconds, path, err);
}

static int load(void *t, uint64_t seed, const char *path, double *seconds, tcb_error *err)
{
    return tcb_neupig_train_load(t, seed, path, seconds, err);
}

static float *params(void *t_, size_t *n)
{
    tcb_neupig_trainer *t = t_;
    *n = t->model.n_params;
    return t->params;
}

/* The template deformed into every frame. */
static int frames(void *t_, float *X, tcb_error *err)
{
    tcb_neupig_trainer *t = t_;
    return tcb_neupig_deform(&t->model, t->params, t->problem, &t->work, X, err);
}

/* The model file's sizes: the architecture's and the template's. */
static cJSON *manifest(const void *self, size_t n_params)
{
    const neupig_method *m = self;
    const tcb_pcgrid_method *b = &m->base;
    const tcb_neupig_arch *a = &m->arch;
    cJSON *j = cJSON_CreateObject();
    cJSON_AddStringToObject(j, "method", "neupig");
    const int sizes[] = {a->levels,    a->base_res,       a->res_step,           a->features,
                         a->normal_res, a->normal_features, a->time_freqs,        a->hidden,
                         b->points,    b->spec.template_faces, b->spec.poisson_depth, b->spec.gt_normals};
    const char *const names[] = {"levels", "base_res", "res_step", "features", "normal_res", "normal_features",
                                 "time_freqs", "hidden", "points", "template_faces", "poisson_depth", "gt_normals"};
    for (size_t k = 0; k < sizeof sizes / sizeof sizes[0]; k++) cJSON_AddNumberToObject(j, names[k], sizes[k]);
    cJSON_AddStringToObject(j, "laplacian", tcb_sobolev_laplacian_names[a->laplacian]);
    cJSON_AddNumberToObject(j, "parameters", (double)n_params);
    return j;
}

static const tcb_pcgrid_hooks hooks = {
    .name = "neupig", .magic = "TCBNPIG2",
    .problem_size = sizeof(problem), .trainer_size = sizeof(tcb_neupig_trainer),
    .problem_init = problem_init, .problem_free = problem_free,
    .trainer_init = trainer_init, .trainer_free = trainer_free,
    .step = step, .done = done, .save = save, .load = load,
    .params = params, .frames = frames, .manifest = manifest,
};

/* ---- the dry run's estimate ---- */

/* The calibrated preset of m's sizes; -1 when one differs from each. */
static int calibrated_preset(const neupig_method *m)
{
    const tcb_pcgrid_method *b = &m->base;
    for (int k = 0; calibrated_presets[k]; k++) {
        int pi = 0;
        while (strcmp(preset_names[pi], calibrated_presets[k])) pi++;
        const neupig_preset *p = &presets[pi];
        if (b->points == p->points && b->spec.template_faces == p->template_faces &&
            b->spec.poisson_depth == p->poisson_depth && m->arch.levels == p->levels &&
            m->arch.features == p->features && m->arch.hidden == p->hidden &&
            b->recon_points == TCB_PCGRID_RECON_POINTS)
            return k;
    }
    return -1;
}

/* A fit: its epochs, after the template (its Poisson surface at depth 10
 * is seconds). */
static void estimate(void *self, const tcb_cost_query *q, tcb_cost_estimate *out)
{
    (void)q;
    tcb_pcgrid_estimate(self, calibrated_presets, calibrated_preset(self), out);
}

const tcb_method_ops tcb_method_neupig = {
    .abi_version = TCB_METHOD_ABI_VERSION,
    .name = "neupig",
    .description = "Neu-PiG (CVPR 2026): a Poisson template of the keyframe moved per vertex by an MLP "
                   "on preconditioned feature grids and time; barycentric read-out",
    .create = create,
    .estimate = estimate,
    .presets = calibrated_presets,
    TCB_PCGRID_SHARED_OPS,
};
