/* cc: unsupervised cycle-consistent deformation (Groueix et al., SGP'19),
 * the network of net.h trained by train.h on triplets of one sequence's
 * frames (params `sampling` = random | knn | neighbors).
 *
 * Presets (overridable key by key; the default is cpu):
 *   paper  C 1024, Z 512, H 64, L 6, 16 triplets of the dataset's input
 *          points (the CC code's network and batch)
 *   cpu    C 128, Z 64, H 32, L 6, 8 triplets of 500 points (sized for
 *          2 CPU cores: one cat-sized sequence in ≤ 30 min)
 *   short  C 32, Z 16, H 16, L 4, 4 triplets of 300 points, 300
 *          iterations (the default benchmark's: a first report with the
 *          fifth method in it, seconds per sequence; far from trained)
 *   tiny   C 16, Z 8, H 8, L 2, 2 triplets of 200 points (tests)
 * Iterations per preset and how they were chosen: docs/protocol.md.
 * `residual` (default false, as the paper) makes the meta-MLP emit an
 * offset, x + 2·tanh(·): the CC code's skip_connections, which its
 * training bypasses (docs/protocol.md C10); the CI training uses it.
 *
 * Read-out (transfer i → j): the GT vertices of i, in i's frame box, are
 * deformed by the network conditioned on (z_i, z_j) with the running
 * batch-norm statistics (PyTorch's eval()), and mapped back through j's
 * box; the harness projects them onto j's GT vertices. This is the "push"
 * direction the per-source-vertex metrics need (CC's own read-out pulls:
 * each target point to its nearest deformed source point). The encoders
 * see fresh input clouds of i and j from the pair's stream (readout
 * "clouds", as every method), or the full vertex sets (readout
 * "vertices", as CC's mesh inference). CC reconstructs no surface: no
 * reconstruct, "-" in CD columns.
 *
 * Checkpoints: the whole training state every `checkpoint_every`
 * iterations in <work_dir>/train.ckpt (train_ckpt.h), continued
 * bit-identically by a killed run; after fit the harness saves the weights
 * and running statistics through save/load below. */
#include <stdlib.h>
#include <string.h>

#include "methods/builtin.h"
#include "methods/cycle/train.h"
#include "methods/cycle/train_ckpt.h"
#include "methods/params.h"
#include "methods/step_cost.h"
#include "neural/train_loop.h"
#include "neural/weights.h"
#include "tcb/json.h"

typedef struct cc_preset {
    tcb_cc_dims d;
    int batch, points;
    long long iterations;
} cc_preset;

static const cc_preset presets[] = {
    {{1024, 512, 64, 6, 0}, 16, 0, 75000},
    {{128, 64, 32, 6, 0}, 8, 500, 10000},
    {{32, 16, 16, 4, 0}, 4, 300, 300},
    {{16, 8, 8, 2, 0}, 2, 200, 60},
};
static const char *const preset_names[] = {"paper", "cpu", "short", "tiny", NULL}; /* presets[k]; default cpu */
static const char *const sampling_names[] = {"random", "knn", "neighbors", NULL}; /* tcb_cc_sampling */
static const char *const readout_names[] = {"clouds", "vertices", NULL};

typedef struct cc_method {
    int preset;                 /* presets[preset]; -1 when a size differs from it */
    tcb_cc_dims d;
    tcb_cc_train_cfg cfg;
    int points;                 /* per training cloud; 0: the dataset's input_points */
    double warmup;              /* fraction of the iterations with the self-reconstruction term */
    int readout_vertices;
    long long checkpoint_every;
    uint64_t seed;              /* of the fit */
    tcb_cc_net *net;            /* NULL before fit or load */
    tcb_cc_trainer *steps;      /* train_steps' training of net; NULL: none */
    tcb_sequence steps_seq;     /* its view of the sequence (train_view) */
    tcb_cc_frame_box *boxes;    /* [n_frames] of the fitted sequence */
    int n_frames;
    struct cc_pair_buffers *pair; /* transfer's, kept from pair to pair; NULL: none yet */
} cc_method;

static int parse_numbers(const cJSON *j, const char *where, const cc_preset *pr, cc_method *c, tcb_error *err)
{
    long long it, C, Z, H, L, batch, points, delta, knn;
    int residual;
    tcb_cc_train_cfg *t = &c->cfg;
    double def_warmup = t->sampler.sampling == TCB_CC_SAMPLE_RANDOM ? 30.0 / 1500 : 30.0 / 500;
    int rc = tcb_json_int(j, "iterations", where, 0, pr->iterations, 1, 100000000, &it, err);
    if (!rc) rc = tcb_json_int(j, "encoder_width", where, 0, pr->d.C, 1, 65536, &C, err);
    if (!rc) rc = tcb_json_int(j, "latent", where, 0, pr->d.Z, 2, 65536, &Z, err);
    if (!rc) rc = tcb_json_int(j, "hidden", where, 0, pr->d.H, 1, 4096, &H, err);
    if (!rc) rc = tcb_json_int(j, "layers", where, 0, pr->d.L, 1, TCB_CC_MAX_META - 1, &L, err);
    if (!rc) rc = tcb_json_bool(j, "residual", where, 0, 0, &residual, err);
    if (!rc) rc = tcb_json_int(j, "batch", where, 0, pr->batch, 2, TCB_CC_MAX_BATCH, &batch, err);
    if (!rc) rc = tcb_json_int(j, "points", where, 0, pr->points, 0, 10000000, &points, err);
    if (!rc) rc = tcb_json_num(j, "warmup", where, 0, def_warmup, 0, 1, &c->warmup, err);
    if (!rc) rc = tcb_json_num(j, "lr", where, 0, 1e-3, 1e-12, 10, &t->lr, err);
    if (!rc) rc = tcb_json_int(j, "delta", where, 0, 1, 1, 1000000, &delta, err);
    if (!rc) rc = tcb_json_int(j, "knn", where, 0, TCB_CC_KNN_K, 1, 100000, &knn, err);
    if (!rc) rc = tcb_json_int(j, "checkpoint_every", where, 0, 500, 0, 100000000, &c->checkpoint_every, err);
    if (!rc) rc = tcb_json_num(j, "divergence", where, 0, 1e4, 0, 1e300, &t->divergence, err);
    if (rc) return rc;
    c->d = (tcb_cc_dims){(int)C, (int)Z, (int)H, (int)L, residual};
    int same = C == pr->d.C && Z == pr->d.Z && H == pr->d.H && L == pr->d.L && batch == pr->batch &&
               points == pr->points;
    c->preset = same ? (int)(pr - presets) : -1;
    t->batch = (int)batch, t->iterations = it, c->points = (int)points;
    t->warmup = (long long)(c->warmup * (double)it + 0.5);
    t->sampler.delta = (int)delta, t->sampler.knn_k = (int)knn;
    return tcb_cc_dims_check(&c->d, where, err);
}

static int parse(const char *params_json, const char *where, cc_method *c, tcb_error *err)
{
    static const char *const keys[] = {"preset", "sampling", "readout", "iterations", "encoder_width", "latent",
                                       "hidden", "layers", "residual", "batch", "points", "warmup", "lr", "delta", "knn",
                                       "checkpoint_every", "divergence", NULL};
    cJSON *j;
    int rc = tcb_params_parse(params_json, where, keys, &j, err);
    if (rc) return rc;
    int pi = 1, si = 0, ri = 0;
    c->cfg.sampler = tcb_cc_sampler_opts_default();
    rc = tcb_json_enum(j, "preset", where, 0, 1, preset_names, &pi, err);
    if (!rc) rc = tcb_json_enum(j, "sampling", where, 0, 0, sampling_names, &si, err);
    if (!rc) rc = tcb_json_enum(j, "readout", where, 0, 0, readout_names, &ri, err);
    c->cfg.sampler.sampling = (tcb_cc_sampling)si, c->readout_vertices = ri == 1;
    if (!rc) rc = parse_numbers(j, where, &presets[pi], c, err);
    cJSON_Delete(j);
    return rc;
}

static int parse_params(const char *params_json, void *c, tcb_error *err)
{
    return parse(params_json, "cc.params", c, err);
}

static int create(const char *params_json, void **self, tcb_error *err)
{
    return tcb_method_create(sizeof(cc_method), "cc", params_json, parse_params, NULL, self, err);
}

/* ---- transfer's buffers ---- */

/* What a pair's transfer computes in: the two clouds, an encoder's and
 * the deformation's activations and scratch, of the sizes of the last
 * pair. Kept from pair to pair because buffers this large, allocated
 * afresh, come from mmap above glibc's threshold and are page-faulted
 * anew each pair: a `tiny` pair cost 18 ms that way against 1.8 ms kept
 * (measured under tcbench calibrate, whose allocations had not raised
 * glibc's threshold). */
typedef struct cc_pair_buffers {
    int n_enc, n_def;            /* the clouds' points, the transferred points */
    float *pi, *pj;              /* [n_enc][3] */
    float *z;                    /* [2][Z] the source's and the target's codes */
    tcb_cc_encoder_cache ec;
    tcb_cc_deform_cache dc;
    float *enc_scratch, *def_scratch;
} cc_pair_buffers;

static void pair_buffers_free(cc_method *c)
{
    cc_pair_buffers *b = c->pair;
    if (!b) return;
    if (b->n_enc) tcb_cc_encoder_cache_free(&b->ec);
    if (b->n_def) tcb_cc_deform_cache_free(&b->dc);
    free(b->pi), free(b->pj), free(b->z), free(b->enc_scratch), free(b->def_scratch);
    free(b);
    c->pair = NULL;
}

/* c->pair for clouds of n_enc points and n_def points to transfer,
 * allocated when its sizes differ. */
static int pair_buffers(cc_method *c, int n_enc, int n_def, tcb_error *err)
{
    if (c->pair && c->pair->n_enc == n_enc && c->pair->n_def == n_def) return TCB_OK;
    pair_buffers_free(c);
    cc_pair_buffers *b = c->pair = calloc(1, sizeof *b);
    if (!b) return tcb_fail(err, TCB_ERR_NOMEM, "cc: out of memory");
    b->pi = malloc((size_t)n_enc * 3 * sizeof *b->pi), b->pj = malloc((size_t)n_enc * 3 * sizeof *b->pj);
    b->z = malloc(2 * (size_t)c->d.Z * sizeof *b->z);
    b->enc_scratch = malloc(tcb_cc_encoder_scratch_floats(&c->d, 1, n_enc) * sizeof(float));
    b->def_scratch = malloc(tcb_cc_deform_scratch_floats(c->net, 1, n_def) * sizeof(float));
    int rc = b->pi && b->pj && b->z && b->enc_scratch && b->def_scratch
                 ? TCB_OK
                 : tcb_fail(err, TCB_ERR_NOMEM, "cc: out of memory");
    if (!rc && !(rc = tcb_cc_encoder_cache_alloc(&b->ec, &c->d, 1, n_enc, err))) b->n_enc = n_enc;
    if (!rc && !(rc = tcb_cc_deform_cache_alloc(&b->dc, c->net, 1, n_def, err))) b->n_def = n_def;
    if (rc) pair_buffers_free(c);
    return rc;
}

static void destroy(void *self)
{
    cc_method *c = self;
    if (!c) return;
    pair_buffers_free(c);
    tcb_cc_trainer_free(c->steps);
    tcb_cc_net_free(c->net);
    free(c->boxes);
    free(c);
}

/* A fresh network, initialised from (seed, "cc/init") when init, and the
 * frame boxes of seq. */
static int new_net(cc_method *c, const tcb_sequence *seq, uint64_t seed, int init, tcb_error *err)
{
    tcb_cc_trainer_free(c->steps); /* it trains the net freed here */
    c->steps = NULL;
    pair_buffers_free(c); /* sized by the net */
    tcb_cc_net_free(c->net), free(c->boxes);
    c->net = NULL, c->boxes = NULL, c->seed = seed, c->n_frames = seq->n_frames;
    int rc = tcb_cc_net_create(&c->d, &c->net, err);
    if (!rc && !(c->boxes = malloc((size_t)seq->n_frames * sizeof *c->boxes)))
        rc = tcb_fail(err, TCB_ERR_NOMEM, "cc: out of memory");
    for (int f = 0; !rc && f < seq->n_frames; f++) rc = tcb_cc_frame_box_compute(seq, f, &c->boxes[f], err);
    if (!rc && init) {
        tcb_rng rng;
        tcb_rng_seed_stream(&rng, seed, "cc/init");
        tcb_cc_net_init(c->net, &rng);
    }
    if (rc) tcb_cc_net_free(c->net), c->net = NULL;
    return rc;
}

/* ---- fit ---- */

/* The training loop's view of a cc training (neural/train_loop.h). */
typedef struct cc_fit {
    tcb_cc_trainer *t;
    const tcb_sequence *seq;
    uint64_t seed;
} cc_fit;

static int fit_step(void *f, double *loss, tcb_error *err)
{
    cc_fit *a = f;
    return tcb_cc_train_step(a->t, a->seq, loss, err);
}

static long long fit_done(const void *f) { return ((const cc_fit *)f)->t->it; }

static int fit_save(const void *f, double seconds, const char *path, tcb_error *err)
{
    const cc_fit *a = f;
    return tcb_cc_train_ckpt_save(a->t, a->seq, a->seed, seconds, path, err);
}

static int fit_load(void *f, const char *path, double *seconds, tcb_error *err)
{
    cc_fit *a = f;
    return tcb_cc_train_ckpt_load(a->t, a->seq, a->seed, path, seconds, err);
}

/* The sequence as the training sees it: clouds of `points` points, a view
 * that differs only there. */
static tcb_sequence train_view(const cc_method *c, const tcb_sequence *seq)
{
    tcb_sequence v = *seq;
    if (c->points > 0) v.input_points = c->points;
    return v;
}

static int fit(void *self, const tcb_sequence *seq, const tcb_fit_ctx *ctx, tcb_error *err)
{
    cc_method *c = self;
    tcb_sequence train_seq = train_view(c, seq);
    cc_fit f = {.seq = &train_seq, .seed = ctx->seed};
    int rc = new_net(c, seq, ctx->seed, 1, err);
    if (!rc) rc = tcb_cc_trainer_create(&c->cfg, c->net, &train_seq, ctx->seed, &f.t, err);
    if (rc) {
        tcb_error_prefix(err, "cc: ");
        return rc;
    }
    tcb_train_loop loop = {.name = "cc", .iterations = c->cfg.iterations, .checkpoint_every = c->checkpoint_every,
                           .ckpt_name = TCB_CC_TRAIN_CKPT, .trainer = &f, .step = fit_step, .done = fit_done,
                           .save = fit_save, .load = fit_load};
    rc = tcb_train_loop_run(&loop, ctx, err);
    tcb_cc_trainer_free(f.t);
    return rc;
}

/* ---- transfer ---- */

/* The code of encoder e for the cloud pts [n][3] (in its frame box, n
 * the pair buffers' n_enc), in evaluation mode, into z [Z]. */
static void encode(const cc_method *c, int e, const float *pts, float *z)
{
    cc_pair_buffers *b = c->pair;
    tcb_cc_encoder_forward(&c->net->p.enc[e], &b->ec, b->enc_scratch, pts, 0);
    memcpy(z, b->ec.z, (size_t)c->d.Z * sizeof(float));
}

/* The encoders' input for frame f into pts [n][3]: a fresh cloud from rng,
 * or the frame's vertices; in f's box. */
static int encoder_input(const cc_method *c, const tcb_sequence *seq, int f, tcb_rng *rng, float *pts, int n,
                         tcb_error *err)
{
    int rc = TCB_OK;
    if (c->readout_vertices) memcpy(pts, tcb_seq_frame(seq, f), (size_t)n * 3 * sizeof *pts);
    else rc = tcb_sequence_draw_points(seq, f, n, seq->draw_with_replacement, rng, pts, err);
    if (!rc) tcb_cc_frame_box_apply(&c->boxes[f], pts, n, pts);
    return rc;
}

static int transfer(void *self, const tcb_sequence *seq, int i, int j, const float *src, int n, float *out,
                    tcb_rng *rng, tcb_error *err)
{
    cc_method *c = self;
    if (!c->net) return tcb_fail(err, TCB_ERR_INTERNAL, "cc: evaluation before fit or load");
    if (i < 0 || j < 0 || i >= seq->n_frames || j >= seq->n_frames || seq->n_frames != c->n_frames)
        return tcb_fail(err, TCB_ERR_INPUT, "cc: pair %d->%d outside frames 0..%d of the fitted sequence", i, j,
                        c->n_frames - 1);
    int n_enc = c->readout_vertices ? seq->n_verts : seq->input_points;
    int rc = pair_buffers(c, n_enc, n, err);
    if (!rc) rc = encoder_input(c, seq, i, rng, c->pair->pi, n_enc, err);
    if (!rc) rc = encoder_input(c, seq, j, rng, c->pair->pj, n_enc, err);
    if (rc) return rc;
    cc_pair_buffers *b = c->pair;
    encode(c, 0, b->pi, b->z);
    encode(c, 1, b->pj, b->z + c->d.Z);
    tcb_cc_frame_box_apply(&c->boxes[i], src, n, out);
    tcb_cc_deform_forward(c->net, &b->dc, b->def_scratch, b->z, b->z + c->d.Z, out, 0);
    memcpy(out, b->dc.out, (size_t)n * 3 * sizeof(float));
    tcb_cc_frame_box_invert(&c->boxes[j], out, n, out);
    return TCB_OK;
}

/* ---- checkpoint: one model file (neural/weights.h), magic "TCBCCMD1" ---- */
#define MAGIC "TCBCCMD1"

static int save(void *self, const char *path, tcb_error *err)
{
    cc_method *c = self;
    if (!c->net) return tcb_fail(err, TCB_ERR_INTERNAL, "%s: cc saved before fit", path);
    cJSON *manifest = tcb_cc_net_manifest(c->net);
    tcb_weight_parts w = tcb_cc_net_weights(c->net);
    int rc = tcb_model_file_write(path, MAGIC, c->seed, manifest, &w, err);
    cJSON_Delete(manifest);
    return rc;
}

static int load(void *self, const tcb_sequence *seq, const char *path, tcb_error *err)
{
    cc_method *c = self;
    uint64_t seed = 0;
    int rc = new_net(c, seq, 0, 0, err);
    if (rc) return rc;
    cJSON *want = tcb_cc_net_manifest(c->net);
    tcb_weight_parts w = tcb_cc_net_weights(c->net);
    rc = tcb_model_file_read(path, MAGIC, want, &seed, &w, err);
    cJSON_Delete(want);
    if (rc) tcb_cc_net_free(c->net), c->net = NULL;
    else c->seed = seed;
    return rc;
}

/* tcb_method_ops.train_steps: fit's training, n steps at a time, after
 * the warm-up phase (the self-reconstruction term of the first few per
 * cent of the iterations), whose steps dominate the fit. */
static int train_steps(void *self, const tcb_sequence *seq, const tcb_fit_ctx *ctx, long long n, tcb_error *err)
{
    cc_method *c = self;
    int rc = TCB_OK;
    if (!c->steps) {
        tcb_cc_train_cfg cfg = c->cfg;
        cfg.warmup = 0;
        rc = new_net(c, seq, ctx->seed, 1, err);
        c->steps_seq = train_view(c, seq);
        if (!rc) rc = tcb_cc_trainer_create(&cfg, c->net, &c->steps_seq, ctx->seed, &c->steps, err);
    }
    double loss;
    for (long long k = 0; !rc && k < n; k++) rc = tcb_cc_train_step(c->steps, &c->steps_seq, &loss, err);
    if (rc) tcb_error_prefix(err, "cc: ");
    return rc;
}

static void estimate(void *self, const tcb_cost_query *q, tcb_cost_estimate *out)
{
    (void)q;
    const cc_method *c = self;
    tcb_step_cost_estimate("cc", preset_names, c->preset, c->cfg.iterations, out);
}

const tcb_method_ops tcb_method_cc = {
    .abi_version = TCB_METHOD_ABI_VERSION,
    .name = "cc",
    .description = "CC: unsupervised cycle-consistent deformation (meta-MLP conditioned on both shapes), "
                   "triplet sampling random | knn | neighbors",
    .create = create,
    .fit = fit,
    .transfer = transfer,
    .save = save,
    .load = load,
    .destroy = destroy,
    .estimate = estimate,
    .presets = preset_names,
    .train_steps = train_steps,
};
