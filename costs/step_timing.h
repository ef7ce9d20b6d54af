/* Measuring costs (costs/step_timing.c): a method's training steps, named
 * units, surface frames and evaluation pairs timed on the calibration
 * sequence, for `tcbench calibrate` (costs/calibrate.c) and
 * bench_train_step, which measure the same steps. */
#ifndef TCB_COSTS_STEP_TIMING_H
#define TCB_COSTS_STEP_TIMING_H

#include "tcb/method.h"
#include "tcb/sequence.h"

/* The sequence costs are measured on: synthetic quadruped_walk,
 * TCB_CALIBRATION_FRAMES frames,
 * pools of TCB_DEFAULT_POOL_SIZE points, clouds of TCB_DEFAULT_INPUT_POINTS
 * (bench_train_step's too). */
int tcb_calibration_sequence(tcb_sequence *s, tcb_error *err);

/* Times train_steps of a created method on seq with ctx->n_threads OpenMP
 * threads (set here): one warm-up step (its seconds, the training's setup
 * included, in first_s), then steps until max_steps or until budget_s is
 * spent, warm-up included, at least one; step_s is their mean. */
typedef struct tcb_step_timing {
    double first_s, step_s;
    int steps;
} tcb_step_timing;
int tcb_time_train_steps(const tcb_method_ops *ops, void *self, const tcb_sequence *seq, const tcb_fit_ctx *ctx,
                         int max_steps, double budget_s, tcb_step_timing *out, tcb_error *err);

/* Times run_unit(unit) as tcb_time_train_steps times steps: an untimed
 * first run, then runs until max_runs or budget_s. */
int tcb_time_unit(const tcb_method_ops *ops, void *self, const tcb_sequence *seq, const tcb_fit_ctx *ctx, int unit,
                  int max_runs, double budget_s, tcb_step_timing *out, tcb_error *err);

/* Times the reconstruction metrics of a frame of a method trained by
 * train_steps, on frames of seq until max_frames or until budget_s is
 * spent, at least one, no warm-up (first_s 0): *mesh_s the mean of the
 * method's surface, step_s the harness's part at `samples` per mesh (both
 * sample sets and the metrics, on the GT meshes of two frames). */
int tcb_time_surface_frames(const tcb_method_ops *ops, void *self, const tcb_sequence *seq, int max_frames,
                            double budget_s, int samples, tcb_step_timing *out, double *mesh_s, tcb_error *err);

/* Mean seconds per pair over n pairs of seq, after one untimed, of a
 * method trained by train_steps: its part (transfer, reconstructions and their Chamfer
 * distances) and the harness's scoring of its transfer. ops NULL: no
 * method, the scoring of the source frame's positions (method_s 0). */
int tcb_time_eval_pairs(const tcb_method_ops *ops, void *self, const tcb_sequence *seq, int n, double *method_s,
                        double *score_s, tcb_error *err);

#endif
