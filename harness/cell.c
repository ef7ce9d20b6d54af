/* One cell of the grid: create the method, fit it (or reload its
 * checkpoint), tell it the pairs when it asks (prepare_pairs, ABI 4),
 * transfer and score every evaluation pair of the split.
 *
 * Two error channels: `merr` collects the method's failures (and bad output
 * it hands back), which end up in the cell file as status failed/diverged;
 * `herr` collects the harness's own failures, which abort the run. */
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "harness/harness_internal.h"
#include "scoring/scoring.h"
#include "tcb/fsutil.h"
#include "tcb/geometry.h"
#include "tcb/metrics.h"
#include "tcb/registry.h"
#include "tcb/sysinfo.h"

/* Per-pair scratch, sized for the sequence once per cell, the scorer (the
 * edge graph of the faces, for the geodesic error) and the box of every
 * frame's vertices a transfer is checked against, also made once. */
typedef struct eval_bufs {
    float *moved;   /* [nv][3] transfer output on frame j */
    int32_t *pred;  /* [nv] predicted vertex ids of frame j */
    double *geo;    /* [nv] each vertex's normalised geodesic error */
    tcb_pair_scorer scorer;
    double box[6];  /* every frame's vertices' (tcb_bbox), for tcb_transfer_check */
} eval_bufs;

static void eval_bufs_free(eval_bufs *b)
{
    free(b->moved);
    free(b->pred);
    free(b->geo);
    tcb_pair_scorer_free(&b->scorer);
    memset(b, 0, sizeof *b);
}

static int eval_bufs_init(const tcb_sequence *seq, eval_bufs *b, tcb_error *herr)
{
    size_t nv = (size_t)seq->n_verts;
    memset(b, 0, sizeof *b);
    b->moved = malloc(nv * 3 * sizeof *b->moved);
    b->pred = malloc(nv * sizeof *b->pred);
    b->geo = malloc(nv * sizeof *b->geo);
    if (!b->moved || !b->pred || !b->geo) {
        eval_bufs_free(b);
        return tcb_fail(herr, TCB_ERR_NOMEM, "out of memory for %zu vertices", nv);
    }
    int rc = tcb_pair_scorer_init(&b->scorer, seq, herr);
    if (rc) eval_bufs_free(b);
    else tcb_bbox(seq->verts, (size_t)seq->n_frames * nv, b->box);
    return rc;
}

int tcb_cell_identity(const tcb_cell_job *job, tcb_cell_result *c, tcb_error *herr)
{
    snprintf(c->dataset, sizeof c->dataset, "%s", job->dataset->name);
    snprintf(c->sequence, sizeof c->sequence, "%s", job->seq->name);
    snprintf(c->role, sizeof c->role, "%s", tcb_role_name(job->split->role));
    snprintf(c->method, sizeof c->method, "%s", job->method->label);
    snprintf(c->method_impl, sizeof c->method_impl, "%s", job->ops->name);
    const char *plugin = tcb_registry_file(job->ops);
    if (plugin) {
        snprintf(c->plugin_path, sizeof c->plugin_path, "%s", plugin);
        snprintf(c->plugin_digest, sizeof c->plugin_digest, "%s", tcb_registry_digest(job->ops));
        c->plugin_abi = job->ops->abi_version;
        snprintf(c->plugin_version, sizeof c->plugin_version, "%s", tcb_method_version(job->ops));
    }
    snprintf(c->git_revision, sizeof c->git_revision, "%s", job->git_revision);
    snprintf(c->split_path, sizeof c->split_path, "%s", job->split_path);
    c->no_faces = job->seq->n_faces == 0;
    c->seed = job->seed;
    c->split_seed = job->split->seed;
    c->load_s = job->load_s;
    c->status = TCB_CELL_OK;
    tcb_summary_init(&c->summary);
    c->params_json = strdup(job->method->params_json);
    if (!c->params_json) return tcb_fail(herr, TCB_ERR_NOMEM, "out of memory");
    return TCB_OK;
}

/* Saved through a temporary name so a kill mid-save leaves no torn
 * checkpoint for the next run to trust. A failed save costs only a refit
 * on resume, so it is a warning, not a cell failure. */
static void save_checkpoint(const tcb_cell_job *job, void *self, double fit_s)
{
    const char *path = job->checkpoint;
    char tmp[TCB_PATH_MAX];
    tcb_error e = {0};
    int rc = tcb_temp_path_for(path, tmp, sizeof tmp, &e);
    if (!rc) {
        rc = job->ops->save(self, tmp, &e);
        /* The record describes the file it is published with and goes
         * first: a published checkpoint always has one. */
        if (!rc) rc = tcb_model_record_save(job, tmp, fit_s, &e);
        if (!rc) rc = tcb_publish(tmp, path, &e);
        else remove(tmp);
    }
    if (rc) tcb_report_log(&job->reporter, TCB_LOG_WARN, "checkpoint not saved: %s", e.msg);
}

/* A method that returned an error without describing it still fails the
 * cell with a readable message. */
void tcb_cell_ensure_error(tcb_error *merr, int rc)
{
    if (merr->code == TCB_OK)
        merr->code = rc > TCB_OK && rc <= TCB_ERR_INTERNAL ? (tcb_status)rc : TCB_ERR_INTERNAL;
    if (!merr->msg[0]) snprintf(merr->msg, sizeof merr->msg, "failed (%s)", tcb_status_name(merr->code));
}

/* A method's state may legitimately be NULL (stateless methods), so
 * success is the return code, never the pointer. */
static int create_method(const tcb_cell_job *job, void **self, tcb_error *merr)
{
    *self = NULL;
    int rc = job->ops->create(job->method->params_json, self, merr);
    if (!rc) return TCB_OK;
    tcb_cell_ensure_error(merr, rc);
    tcb_error_prefix(merr, "create: ");
    return rc;
}

/* What fit and prepare_pairs are told; resumed_fit_s may be NULL. */
static tcb_fit_ctx fit_ctx(const tcb_cell_job *job, double *resumed_fit_s)
{
    return (tcb_fit_ctx){(uint64_t)job->seed, job->threads, job->work_dir, job->reporter, resumed_fit_s,
                         job->interrupted, job->interrupt_arg};
}

/* create + (load | fit [+ save]); on failure nothing is left to destroy.
 * *fit_s (fit_s may be NULL) gets the whole fit's seconds: this process's,
 * plus what a resumed training or a reused checkpoint cost before. */
static int prepare_method(const tcb_cell_job *job, void **self, double *fit_s, tcb_error *merr)
{
    const tcb_method_ops *ops = job->ops;
    double t0 = tcb_now_seconds(), earlier = 0;
    if (job->require_checkpoint && ops->load && !tcb_is_file(job->checkpoint))
        return tcb_fail(merr, TCB_ERR_IO, "%s: no such file: the cell has no fitted model yet",
                        job->checkpoint);
    int rc = create_method(job, self, merr);
    if (rc) return rc;
    if (ops->load && job->reuse_checkpoint && tcb_is_file(job->checkpoint)) {
        tcb_error le = {0};
        double recorded = 0;
        /* The record first: a file that is not this cell's is never loaded. */
        if (tcb_model_record_check(job, &recorded, &le) == TCB_OK &&
            ops->load(*self, job->seq, job->checkpoint, &le) == TCB_OK) {
            if (fit_s) *fit_s = recorded + tcb_now_seconds() - t0;
            return TCB_OK;
        }
        if (job->require_checkpoint) {
            ops->destroy(*self);
            return tcb_fail(merr, le.code ? le.code : TCB_ERR_INPUT, "%s", le.msg);
        }
        /* A model half-loaded from a bad checkpoint is not trusted: start over. */
        tcb_report_log(&job->reporter, TCB_LOG_WARN, "%s: not reused (%s); fitting again",
                       job->checkpoint, le.msg);
        ops->destroy(*self);
        rc = create_method(job, self, merr);
        if (rc) return rc;
    }
    tcb_fit_ctx ctx = fit_ctx(job, &earlier);
    rc = ops->fit(*self, job->seq, &ctx, merr);
    double spent = earlier + tcb_now_seconds() - t0;
    if (fit_s) *fit_s = spent;
    if (rc) {
        tcb_cell_ensure_error(merr, rc);
        tcb_error_prefix(merr, "fit: ");
        ops->destroy(*self);
        return rc;
    }
    if (ops->save) save_checkpoint(job, *self, spent);
    return TCB_OK;
}

int tcb_cell_prepare_pairs(const tcb_cell_job *job, void *self, const int *pairs, int first, int n,
                           tcb_error *merr)
{
    const tcb_method_ops *ops = job->ops;
    if (ops->abi_version < 4 || !ops->prepare_pairs) return TCB_OK;
    tcb_fit_ctx ctx = fit_ctx(job, NULL);
    int rc = ops->prepare_pairs(self, job->seq, pairs, first, n, &ctx, merr);
    if (!rc) return TCB_OK;
    tcb_cell_ensure_error(merr, rc);
    tcb_error_prefix(merr, "prepare_pairs %d-%d: ", first, first + n - 1);
    return rc;
}

/* The split's pairs first .. first + n - 1, announced. */
static int prepare_split_pairs(const tcb_cell_job *job, void *self, int first, int n, tcb_error *merr)
{
    return tcb_cell_prepare_pairs(job, self, job->split->pairs + 2 * first, first, n, merr);
}

/* Reconstruct `frame` in the context of pair (i, j) and score it against
 * the frame's GT vertices; the points go to *keep (NULL: freed). A method
 * of ABI >= 4 may decline (TCB_ERR_UNSUPPORTED): *cd is then NaN, the CD
 * columns' "-". */
static void reconstruction_cd(const tcb_cell_job *job, void *self, int i, int j, int frame,
                              tcb_rng *rng, double *cd, float **keep, int *keep_n,
                              tcb_error *merr, tcb_error *herr)
{
    const tcb_sequence *seq = job->seq;
    float *pts = NULL;
    int n = 0;
    int rc = job->ops->reconstruct(self, seq, i, j, frame, rng, &pts, &n, merr);
    if (rc == TCB_ERR_UNSUPPORTED && job->ops->abi_version >= 4) {
        tcb_error_clear(merr);
        free(pts);
        *cd = NAN;
        return;
    }
    if (rc) {
        tcb_cell_ensure_error(merr, rc);
        tcb_error_prefix(merr, "reconstruct frame %d (pair %d->%d): ", frame, i, j);
    } else if (!pts || n <= 0)
        tcb_fail(merr, TCB_ERR_INTERNAL, "reconstruct frame %d (pair %d->%d): returned no points",
                 frame, i, j);
    else if (!tcb_all_finite(pts, (size_t)n * 3)) /* the method's output is wrong: a failed cell */
        tcb_fail(merr, TCB_ERR_INPUT,
                 "reconstruct frame %d (pair %d->%d): returned a non-finite point", frame, i, j);
    else
        tcb_chamfer(pts, n, tcb_seq_frame(seq, frame), seq->n_verts, cd, herr);
    if (keep && !merr->code && !herr->code) {
        *keep = pts, *keep_n = n;
        return;
    }
    free(pts);
}

/* The method's transfer of frame i's GT vertices to frame j into moved,
 * checked (tcb_transfer_check against the sequence's box); k numbers the
 * pair in messages. */
static int transfer_pair(const tcb_cell_job *job, void *self, int i, int j, int k, tcb_rng *rng,
                         const double box[6], float *moved, tcb_error *merr)
{
    const tcb_sequence *seq = job->seq;
    int nv = seq->n_verts;
    int rc = job->ops->transfer(self, seq, i, j, tcb_seq_frame(seq, i), nv, moved, rng, merr);
    if (rc) {
        tcb_cell_ensure_error(merr, rc);
        tcb_error_prefix(merr, "transfer %d->%d (pair %d): ", i, j, k);
        return rc;
    }
    if ((rc = tcb_transfer_check(box, seq, j, moved, merr)))
        tcb_error_prefix(merr, "transfer %d->%d (pair %d): ", i, j, k);
    return rc;
}

/* Pair k of the split into rec and the summary; with `cap`, its metrics
 * and reconstructions are kept there too. Failures land in merr (the
 * method's) or herr (the harness's); the caller checks both. */
static void eval_pair(const tcb_cell_job *job, void *self, int k, eval_bufs *b,
                      tcb_pair_record *rec, tcb_summary *sum, tcb_pair_capture *cap,
                      tcb_error *merr, tcb_error *herr)
{
    const tcb_sequence *seq = job->seq;
    int i = job->split->pairs[2 * k], j = job->split->pairs[2 * k + 1];
    char label[TCB_PATH_MAX];
    snprintf(label, sizeof label, "eval/%s/%s/%d", job->dataset->name, seq->name, k);
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, (uint64_t)job->seed, label);
    if (transfer_pair(job, self, i, j, k, &rng, b->box, b->moved, merr)) return;
    double cd = NAN;
    if (job->ops->reconstruct) {
        double cd_i = 0, cd_j = 0;
        reconstruction_cd(job, self, i, j, i, &rng, &cd_i, cap ? &cap->recon[0] : NULL,
                          cap ? &cap->n_recon[0] : NULL, merr, herr);
        if (!merr->code && !herr->code)
            reconstruction_cd(job, self, i, j, j, &rng, &cd_j, cap ? &cap->recon[1] : NULL,
                              cap ? &cap->n_recon[1] : NULL, merr, herr);
        if (merr->code || herr->code) return;
        cd = 0.5 * (cd_i + cd_j);
    }
    /* Scored last, on the path scored cells take too; the metrics draw no
     * random numbers, so scoring after the reconstructions changes nothing. */
    tcb_pair_prediction pred = {i, j, b->moved, b->pred, cd, b->geo};
    tcb_pair_metrics pm;
    if (tcb_cell_score_pair(&b->scorer, &pred, rec, sum, &pm, herr)) return;
    if (cap) cap->i = i, cap->j = j, cap->metrics = pm;
}

#define CLIP_PAIRS (TCB_CLIP_FRAMES - 1)

/* Clip c of job->clips: its frame 0 (start) transferred to each of its
 * frames 1 .. 16, and the tracking error of each (the transferred points
 * as the method gave them, not projected: DynoSurf scores its predicted
 * vertices) into rec. Each transfer draws from a stream of its own frames,
 * the same whether or not the pairs are evaluated too. */
static void eval_clip(const tcb_cell_job *job, void *self, int c, int first, const double box[6], float *moved,
                      tcb_clip_record *rec, tcb_error *merr)
{
    const tcb_sequence *seq = job->seq;
    int s = job->clips->starts[c];
    rec->start = s;
    rec->corr = 0;
    for (int t = 1; t < TCB_CLIP_FRAMES; t++) {
        char label[TCB_PATH_MAX];
        snprintf(label, sizeof label, "clip/%s/%s/%d/%d", job->dataset->name, seq->name, s, t);
        tcb_rng rng;
        tcb_rng_seed_stream(&rng, (uint64_t)job->seed, label);
        if (transfer_pair(job, self, s, s + t, first + t - 1, &rng, box, moved, merr)) return;
        rec->err[t - 1] = tcb_corr_frame(moved, tcb_seq_frame(seq, s + t), seq->n_verts);
        rec->corr += rec->err[t - 1] / CLIP_PAIRS;
    }
}

/* The clips' pairs (s, s + 1) .. (s, s + 16) of every clip in order, for
 * prepare_pairs; malloc'ed [n_clips * 16][2], NULL when out of memory. */
static int *clip_pairs(const tcb_split *clips)
{
    int *pairs = malloc((size_t)clips->n_clips * CLIP_PAIRS * 2 * sizeof *pairs);
    for (int c = 0; pairs && c < clips->n_clips; c++)
        for (int t = 1; t < TCB_CLIP_FRAMES; t++) {
            int m = c * CLIP_PAIRS + t - 1;
            pairs[2 * m] = clips->starts[c], pairs[2 * m + 1] = clips->starts[c] + t;
        }
    return pairs;
}

/* A stop request ends the evaluation between two pairs. */
static int stop_requested(const tcb_cell_job *job, int done, int total, tcb_error *herr)
{
    if (!job->interrupted || !job->interrupted(job->interrupt_arg)) return 0;
    tcb_fail(herr, TCB_ERR_INTERRUPTED, "stopped at pair %d of %d of the evaluation (the fitted model is kept)",
             done, total);
    return 1;
}

/* The clip protocol's clips after the split's pairs; their pairs are
 * numbered on from the split's (prepare_pairs, messages). */
static void evaluate_clips(const tcb_cell_job *job, void *self, eval_bufs *b, tcb_cell_result *c,
                           const char *label, int total, tcb_error *merr, tcb_error *herr)
{
    const tcb_split *clips = job->clips;
    int first = job->split->n_pairs;
    int *pairs = clip_pairs(clips);
    c->clips = calloc((size_t)clips->n_clips, sizeof *c->clips);
    if (!pairs || !c->clips) {
        free(pairs);
        tcb_fail(herr, TCB_ERR_NOMEM, "out of memory for %d clips", clips->n_clips);
        return;
    }
    tcb_cell_prepare_pairs(job, self, pairs, first, clips->n_clips * CLIP_PAIRS, merr);
    free(pairs);
    snprintf(c->clips_path, sizeof c->clips_path, "%s", job->clips_path);
    c->clips_seed = clips->seed;
    for (int k = 0; k < clips->n_clips && !merr->code; k++) {
        int done = first + k * CLIP_PAIRS;
        if (stop_requested(job, done, total, herr)) return;
        eval_clip(job, self, k, done, b->box, b->moved, &c->clips[k], merr);
        c->clips[k].corr_mesh = NAN;
        if (!merr->code && tcb_method_has_surface(job->ops)) tcb_cell_corr_mesh(job, self, k, &c->clips[k], merr, herr);
        if (merr->code || herr->code) break;
        tcb_stat_push(&c->summary.corr, c->clips[k].corr);
        if (!isnan(c->clips[k].corr_mesh)) tcb_stat_push(&c->summary.corr_mesh, c->clips[k].corr_mesh);
        tcb_report_progress(&job->reporter, done + CLIP_PAIRS, total, label);
    }
    c->n_clips = clips->n_clips;
}

static void evaluate(const tcb_cell_job *job, void *self, tcb_cell_result *c, tcb_error *merr,
                     tcb_error *herr)
{
    const tcb_split *split = job->split;
    int total = split->n_pairs + (job->clips ? job->clips->n_clips * CLIP_PAIRS : 0);
    eval_bufs b;
    if (eval_bufs_init(job->seq, &b, herr)) return;
    c->pairs = calloc((size_t)split->n_pairs + 1, sizeof *c->pairs);
    if (!c->pairs) {
        tcb_fail(herr, TCB_ERR_NOMEM, "out of memory for %d pairs", split->n_pairs);
    } else {
        char label[TCB_CELL_LABEL_MAX];
        tcb_cell_label(label, sizeof label, job->dataset->name, job->seq->name,
                       job->method->label, job->seed);
        tcb_report_progress(&job->reporter, 0, total, label);
        if (split->n_pairs > 0) prepare_split_pairs(job, self, 0, split->n_pairs, merr);
        for (int k = 0; k < split->n_pairs && !merr->code && !herr->code; k++) {
            if (stop_requested(job, k, total, herr)) break;
            eval_pair(job, self, k, &b, &c->pairs[k], &c->summary, NULL, merr, herr);
            tcb_report_progress(&job->reporter, k + 1, total, label);
        }
        c->n_pairs = split->n_pairs;
        if (job->clips && !merr->code && !herr->code) evaluate_clips(job, self, &b, c, label, total, merr, herr);
        if (!merr->code && !herr->code) tcb_cell_surface_metrics(job, self, c, merr, herr);
    }
    eval_bufs_free(&b);
}

/* A failed cell keeps its identity, timings and message, no numbers. */
static void record_failure(tcb_cell_result *c, const tcb_error *merr)
{
    c->status = merr->code == TCB_ERR_NUMERIC ? TCB_CELL_DIVERGED : TCB_CELL_FAILED;
    snprintf(c->message, sizeof c->message, "%s", merr->msg);
    tcb_cell_drop_rows(c);
    tcb_summary_init(&c->summary);
}

/* The cell's OpenMP thread count (job->threads; 0 leaves the process's)
 * over the whole cell, evaluation and metrics included, not only the fit:
 * two `--threads 1` processes on two cores would otherwise each evaluate
 * with every core's worth of threads, and their barriers spin against each
 * other (an eval 40x slower than its fit was measured so). Returns the
 * previous count for restore_threads. */
static int use_threads(const tcb_cell_job *job)
{
    int prev = omp_get_max_threads();
    if (job->threads > 0) omp_set_num_threads(job->threads);
    return prev;
}

static void restore_threads(int prev) { omp_set_num_threads(prev); }

static int run_cell(const tcb_cell_job *job, tcb_cell_result *out, tcb_error *err)
{
    memset(out, 0, sizeof *out);
    tcb_error merr = {0}, herr = {0};
    for (int k = 0; k < 2 * job->split->n_pairs; k++)
        if (job->split->pairs[k] < 0 || job->split->pairs[k] >= job->seq->n_frames)
            return tcb_fail(err, TCB_ERR_INPUT, "%s: pair %d names frame %d of %d", job->split_path,
                            k / 2, job->split->pairs[k], job->seq->n_frames);
    if (tcb_cell_identity(job, out, &herr)) goto fail;

    void *self;
    int prepared = prepare_method(job, &self, &out->fit_s, &merr) == TCB_OK;
    double t1 = tcb_now_seconds();
    if (prepared) {
        snprintf(out->normals, sizeof out->normals, "%s", tcb_method_normals(job->ops, self, job->seq));
        evaluate(job, self, out, &merr, &herr);
        job->ops->destroy(self);
    }
    out->eval_s = tcb_now_seconds() - t1;
    out->peak_rss_kb = tcb_peak_rss_kb();
    if (merr.code == TCB_ERR_INTERRUPTED) herr = merr; /* not the cell's failure: it resumes */
    if (herr.code) goto fail;
    if (merr.code) record_failure(out, &merr);
    return TCB_OK;
fail:
    tcb_cell_free(out);
    return tcb_fail(err, herr.code, "%s", herr.msg);
}

static int eval_one_pair(const tcb_cell_job *job, int k, tcb_pair_capture *out, tcb_error *err)
{
    memset(out, 0, sizeof *out);
    if (k < 0 || k >= job->split->n_pairs)
        return tcb_fail(err, TCB_ERR_INPUT, "%s: no pair %d (the split has %d: 0 to %d)",
                        job->split_path, k, job->split->n_pairs, job->split->n_pairs - 1);
    tcb_error merr = {0}, herr = {0};
    eval_bufs b;
    void *self;
    int ready = eval_bufs_init(job->seq, &b, &herr) == TCB_OK;
    if (ready && prepare_method(job, &self, NULL, &merr) == TCB_OK) {
        tcb_pair_record rec;
        tcb_summary sum;
        tcb_summary_init(&sum);
        if (prepare_split_pairs(job, self, k, 1, &merr) == TCB_OK) {
            eval_pair(job, self, k, &b, &rec, &sum, out, &merr, &herr);
            out->cd = rec.cd;
        }
        job->ops->destroy(self);
    }
    /* The capture keeps the per-vertex arrays; the graph goes. */
    out->moved = b.moved, out->pred = b.pred, out->geo = b.geo;
    b.moved = NULL, b.pred = NULL, b.geo = NULL;
    eval_bufs_free(&b);
    if (!herr.code && !merr.code) return TCB_OK;
    tcb_pair_capture_free(out);
    if (herr.code) return tcb_fail(err, herr.code, "%s", herr.msg);
    return tcb_fail(err, merr.code, "%s: %s", job->method->label, merr.msg);
}

int tcb_cell_run(const tcb_cell_job *job, tcb_cell_result *out, tcb_error *err)
{
    int prev = use_threads(job);
    int rc = run_cell(job, out, err);
    restore_threads(prev);
    return rc;
}

int tcb_cell_eval_pair(const tcb_cell_job *job, int k, tcb_pair_capture *out, tcb_error *err)
{
    int prev = use_threads(job);
    int rc = eval_one_pair(job, k, out, err);
    restore_threads(prev);
    return rc;
}

int tcb_cell_use_method(const tcb_cell_job *job, tcb_method_use use, void *ctx, tcb_error *err)
{
    int prev = use_threads(job);
    tcb_error merr = {0};
    void *self;
    int rc = prepare_method(job, &self, NULL, &merr);
    if (!rc) {
        rc = use(ctx, self, &merr);
        if (rc) tcb_cell_ensure_error(&merr, rc);
        job->ops->destroy(self);
    }
    restore_threads(prev);
    return rc ? tcb_fail(err, merr.code, "%s: %s", job->method->label, merr.msg) : TCB_OK;
}

void tcb_pair_capture_free(tcb_pair_capture *c)
{
    free(c->moved);
    free(c->pred);
    free(c->geo);
    free(c->recon[0]);
    free(c->recon[1]);
    memset(c, 0, sizeof *c);
}
