/* Timing a method's training steps, units, evaluation pairs and
 * reconstruction metrics (costs/calibration.h): the measurements
 * `tcbench calibrate` makes, the steps' also bench_train_step's. */
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "costs/calibration.h"
#include "costs/step_timing.h"
#include "scoring/scoring.h"
#include "tcb/metrics.h"
#include "tcb/rng.h"
#include "tcb/split.h"
#include "tcb/synth.h"

int tcb_calibration_sequence(tcb_sequence *s, tcb_error *err)
{
    int rc = tcb_synth_generate("quadruped_walk", 1, TCB_CALIBRATION_FRAMES, s, err);
    if (!rc) rc = tcb_sequence_normalize(s, TCB_NORM_FIRST_FRAME, err);
    if (!rc) rc = tcb_sequence_sample_pools(s, TCB_DEFAULT_POOL_SIZE, 1, err);
    if (rc) {
        tcb_sequence_free(s);
        return rc;
    }
    s->input_points = TCB_DEFAULT_INPUT_POINTS, s->draw_with_replacement = 0;
    return TCB_OK;
}

/* One call of what is timed. */
typedef int (*timed_call)(const void *arg, tcb_error *err);

/* An untimed first call (its seconds in first_s), then calls until max or
 * until budget_s is spent, the first included, at least one. */
static int time_calls(timed_call call, const void *arg, int max, double budget_s, tcb_step_timing *out,
                      tcb_error *err)
{
    double t0 = tcb_now_seconds();
    int rc = call(arg, err);
    double t1 = tcb_now_seconds(), spent = 0;
    out->first_s = t1 - t0, out->steps = 0;
    while (!rc && out->steps < max && (out->steps == 0 || out->first_s + spent < budget_s)) {
        rc = call(arg, err);
        out->steps++;
        spent = tcb_now_seconds() - t1;
    }
    out->step_s = out->steps ? spent / out->steps : NAN;
    return rc;
}

typedef struct method_call {
    const tcb_method_ops *ops;
    void *self;
    const tcb_sequence *seq;
    const tcb_fit_ctx *ctx;
    int unit;
} method_call;

static int one_step(const void *arg, tcb_error *err)
{
    const method_call *c = arg;
    return c->ops->train_steps(c->self, c->seq, c->ctx, 1, err);
}

static int one_unit(const void *arg, tcb_error *err)
{
    const method_call *c = arg;
    return c->ops->run_unit(c->self, c->seq, c->ctx, c->unit, err);
}

int tcb_time_train_steps(const tcb_method_ops *ops, void *self, const tcb_sequence *seq, const tcb_fit_ctx *ctx,
                         int max_steps, double budget_s, tcb_step_timing *out, tcb_error *err)
{
    omp_set_num_threads(ctx->n_threads);
    const method_call c = {ops, self, seq, ctx, 0};
    return time_calls(one_step, &c, max_steps, budget_s, out, err);
}

int tcb_time_unit(const tcb_method_ops *ops, void *self, const tcb_sequence *seq, const tcb_fit_ctx *ctx, int unit,
                  int max_runs, double budget_s, tcb_step_timing *out, tcb_error *err)
{
    omp_set_num_threads(ctx->n_threads);
    const method_call c = {ops, self, seq, ctx, unit};
    return time_calls(one_unit, &c, max_runs, budget_s, out, err);
}

/* The method's surface of `frame`, made and freed; its seconds. */
static int time_mesh(const tcb_method_ops *ops, void *self, const tcb_sequence *seq, int frame, double *seconds,
                     tcb_error *err)
{
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 0, "calibrate/surface");
    tcb_uv_mesh m = {0, 0, 0, NULL, NULL, NULL, NULL};
    double t0 = tcb_now_seconds();
    int rc = ops->surface(self, seq, frame, &rng, &m, err);
    *seconds = tcb_now_seconds() - t0;
    tcb_uv_mesh_free(&m);
    return rc;
}

/* The harness's part of the metrics of frame f: n samples of f's GT mesh,
 * standing for a trained method's surface (an untrained one's heaps of
 * points make the nearest-neighbour queries many times slower than a
 * cell's), against n of the frame half the sequence away (a surface some
 * way off the GT: the queries slow down with the distance); its seconds.
 * buf: [4][n][3]. */
static int time_metrics(const tcb_sequence *seq, int f, int n, float *buf, double *seconds, tcb_error *err)
{
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 0, "calibrate/surface_gt");
    size_t len = (size_t)n * 3;
    const float *a = tcb_seq_frame(seq, f), *b = tcb_seq_frame(seq, (f + seq->n_frames / 2) % seq->n_frames);
    double v[TCB_N_RECON], t0 = tcb_now_seconds();
    int rc = tcb_recon_sample(a, seq->faces, seq->n_faces, n, &rng, buf, buf + len, err);
    if (!rc) rc = tcb_recon_sample(b, seq->faces, seq->n_faces, n, &rng, buf + 2 * len, buf + 3 * len, err);
    if (!rc) rc = tcb_recon_metrics(buf, buf + len, n, buf + 2 * len, buf + 3 * len, n, v, err);
    *seconds = tcb_now_seconds() - t0;
    return rc;
}

int tcb_time_surface_frames(const tcb_method_ops *ops, void *self, const tcb_sequence *seq, int max_frames,
                            double budget_s, int samples, tcb_step_timing *out, double *mesh_s, tcb_error *err)
{
    float *buf = malloc((size_t)samples * 12 * sizeof *buf);
    int rc = buf ? TCB_OK : tcb_fail(err, TCB_ERR_NOMEM, "out of memory for %d surface samples", samples);
    double t0 = tcb_now_seconds(), metrics = 0, mesh = 0, m = 0;
    out->first_s = 0, out->steps = 0, *mesh_s = 0;
    /* no warm-up: a cell's frames share nothing but the sample buffers */
    while (!rc && out->steps < max_frames && (out->steps == 0 || tcb_now_seconds() - t0 < budget_s)) {
        int f = out->steps % seq->n_frames;
        rc = time_mesh(ops, self, seq, f, &mesh, err);
        if (!rc) rc = time_metrics(seq, f, samples, buf, &m, err);
        *mesh_s += mesh, metrics += m, out->steps++;
    }
    out->step_s = metrics / out->steps, *mesh_s /= out->steps;
    free(buf);
    return rc;
}

/* Frame i's reconstruction in the context of pair (i, j) and its Chamfer
 * distance, as the harness's evaluation computes them; a method that
 * declines costs nothing. */
static int reconstruct_frame(const tcb_method_ops *ops, void *self, const tcb_sequence *seq, int i, int j, int frame,
                             tcb_rng *rng, tcb_error *err)
{
    float *pts = NULL;
    int n = 0;
    double cd;
    int rc = ops->reconstruct(self, seq, i, j, frame, rng, &pts, &n, err);
    if (rc == TCB_ERR_UNSUPPORTED) tcb_error_clear(err), rc = TCB_OK;
    else if (!rc && pts && n > 0) rc = tcb_chamfer(pts, n, tcb_seq_frame(seq, frame), seq->n_verts, &cd, err);
    free(pts);
    return rc;
}

/* Pair k's method part into moved; its seconds added to *method_s. */
static int method_pair(const tcb_method_ops *ops, void *self, const tcb_sequence *seq, int i, int j, float *moved,
                       double *method_s, tcb_error *err)
{
    if (!ops) { /* no method: the source frame's positions, as the nearest baseline carries them */
        memcpy(moved, tcb_seq_frame(seq, i), (size_t)seq->n_verts * 3 * sizeof *moved);
        return TCB_OK;
    }
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 0, "calibrate/eval");
    double t0 = tcb_now_seconds();
    int rc = ops->transfer(self, seq, i, j, tcb_seq_frame(seq, i), seq->n_verts, moved, &rng, err);
    if (!rc && ops->reconstruct) rc = reconstruct_frame(ops, self, seq, i, j, i, &rng, err);
    if (!rc && ops->reconstruct) rc = reconstruct_frame(ops, self, seq, i, j, j, &rng, err);
    *method_s += tcb_now_seconds() - t0;
    return rc;
}

int tcb_time_eval_pairs(const tcb_method_ops *ops, void *self, const tcb_sequence *seq, int n, double *method_s,
                        double *score_s, tcb_error *err)
{
    int nv = seq->n_verts;
    float *moved = malloc((size_t)nv * 3 * sizeof *moved);
    int32_t *pred = malloc((size_t)nv * sizeof *pred);
    tcb_pair_scorer scorer;
    int rc = moved && pred ? tcb_pair_scorer_init(&scorer, seq, err) : tcb_fail(err, TCB_ERR_NOMEM, "out of memory");
    *method_s = *score_s = 0;
    /* pairs drawn as a split draws them (an ordered pair of distinct frames,
     * uniform): the scoring's geodesic search walks from each vertex's
     * prediction to its truth, longer for frames further apart */
    tcb_rng pairs;
    tcb_rng_seed_stream(&pairs, 0, "calibrate/pairs");
    /* pair -1, untimed, sets up what a cell's evaluation sets up once */
    for (int k = -1; !rc && k < n; k++) {
        int i = (int)tcb_rng_below(&pairs, (uint32_t)seq->n_frames);
        int j = tcb_pair_sample(TCB_PAIRS_RANDOM, 0, seq->n_frames, 0, seq->n_frames, i, &pairs);
        double before = *method_s;
        rc = method_pair(ops, self, seq, i, j, moved, method_s, err);
        tcb_pair_prediction p = {i, j, moved, pred, NAN, NULL};
        tcb_pair_record rec;
        tcb_summary sum;
        tcb_summary_init(&sum);
        double t0 = tcb_now_seconds();
        if (!rc) rc = tcb_cell_score_pair(&scorer, &p, &rec, &sum, NULL, err);
        if (k < 0) *method_s = before;
        else *score_s += tcb_now_seconds() - t0;
    }
    if (moved && pred) tcb_pair_scorer_free(&scorer);
    free(moved), free(pred);
    *method_s /= n, *score_s /= n;
    return rc;
}
