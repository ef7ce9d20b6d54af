/* Timing a method's training steps and evaluation pairs
 * (harness/calibration.h): the one measurement `tcbench calibrate` and
 * bench_train_step both make. */
#include <math.h>
#include <omp.h>
#include <stdlib.h>

#include "harness/calibration.h"
#include "harness/internal.h"
#include "tcb/metrics.h"
#include "tcb/synth.h"

enum { CALIBRATION_FRAMES = 6 };

int tcb_calibration_sequence(tcb_sequence *s, tcb_error *err)
{
    int rc = tcb_synth_generate("quadruped_walk", 1, CALIBRATION_FRAMES, s, err);
    if (!rc) rc = tcb_sequence_normalize(s, TCB_NORM_FIRST_FRAME, err);
    if (!rc) rc = tcb_sequence_sample_pools(s, TCB_DEFAULT_POOL_SIZE, 1, err);
    if (rc) {
        tcb_sequence_free(s);
        return rc;
    }
    s->input_points = TCB_DEFAULT_INPUT_POINTS, s->draw_with_replacement = 0;
    return TCB_OK;
}

int tcb_time_train_steps(const tcb_method_ops *ops, void *self, const tcb_sequence *seq, const tcb_fit_ctx *ctx,
                         int max_steps, double budget_s, tcb_step_timing *out, tcb_error *err)
{
    omp_set_num_threads(ctx->n_threads);
    double t0 = tcb_now_seconds();
    int rc = ops->train_steps(self, seq, ctx, 1, err);
    double t1 = tcb_now_seconds(), spent = 0;
    out->first_s = t1 - t0, out->steps = 0;
    while (!rc && out->steps < max_steps && (out->steps == 0 || out->first_s + spent < budget_s)) {
        rc = ops->train_steps(self, seq, ctx, 1, err);
        out->steps++;
        spent = tcb_now_seconds() - t1;
    }
    out->step_s = out->steps ? spent / out->steps : NAN;
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
    /* pair -1, untimed, sets up what a cell's evaluation sets up once */
    for (int k = -1; !rc && k < n; k++) {
        int m = k + 1, i = m % seq->n_frames, j = (i + 1 + m / seq->n_frames) % seq->n_frames;
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
