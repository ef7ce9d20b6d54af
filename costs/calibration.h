/* Measured costs: what `tcbench calibrate` measures on the machine it runs
 * on, and what `tcbench run --dry-run` prices cells with (docs/cluster.md,
 * "Sizing an allocation").
 *
 * A calibration file holds, for the machine it names, the seconds of
 *   - one training step of each trained method at each preset (kind step),
 *   - the method's part of an evaluation pair: the transfer of frame i's
 *     vertices and the reconstruction of both frames with their Chamfer
 *     distances (kind eval_pair),
 *   - one of a method's named units (kind unit: a registration, a template
 *     mesh; tcb_method_ops.units) at each preset,
 *   - the reconstruction metrics of one frame of a method with a surface:
 *     the method's surface of the frame (kind surface_mesh), and the
 *     harness's part, both sample sets and the metrics, at `size` samples
 *     per mesh (kind surface_frame),
 *   - the harness's scoring of a pair: projection, metrics, geodesic error
 *     (kind score_pair, no method),
 * each at the thread counts measured, on the calibration sequence
 * (tcb_calibration_sequence), whose vertex and frame counts it records. */
#ifndef TCB_HARNESS_CALIBRATION_H
#define TCB_HARNESS_CALIBRATION_H

#include <stdio.h>

#include "tcb/method.h"
#include "tcb/sequence.h"

typedef enum tcb_cost_kind {
    TCB_COST_STEP,
    TCB_COST_EVAL_PAIR,
    TCB_COST_SCORE_PAIR,
    TCB_COST_UNIT,
    TCB_COST_SURFACE_FRAME,
    TCB_COST_SURFACE_MESH,
    TCB_COST_KINDS
} tcb_cost_kind;

/* The calibration sequence's frames (tcb_calibration_sequence). */
#define TCB_CALIBRATION_FRAMES 6

typedef struct tcb_cost_entry {
    tcb_cost_kind kind;
    char method[64], preset[32]; /* "" for score_pair */
    int threads;
    int samples;                 /* steps or pairs timed */
    double seconds;              /* mean per step, pair, unit or frame */
    char unit[32];               /* kind unit: its name; else "" */
    int size;                    /* kind surface_frame: samples per mesh; else 0 */
} tcb_cost_entry;

typedef struct tcb_calibration {
    char origin[4096];    /* the file it was read from, or "built-in" */
    char machine[160];    /* "CPU model, N cores": names it in the dry run's bases */
    char *machine_json;   /* the whole description (CPU, cores, library versions), as JSON text */
    int n_verts;          /* the calibration sequence's: the pairs' costs were measured at it */
    int n_frames;         /* and its frames (an epoch's steps were measured over them) */
    tcb_cost_entry *entries;
    int n, cap;
} tcb_calibration;

void tcb_calibration_free(tcb_calibration *c);
int tcb_calibration_add(tcb_calibration *c, const tcb_cost_entry *e, tcb_error *err);
int tcb_calibration_parse(const char *text, const char *origin, tcb_calibration *out, tcb_error *err);
int tcb_calibration_write(const tcb_calibration *c, const char *path, tcb_error *err);

/* The committed defaults (calibration/default.json, compiled in). */
int tcb_calibration_builtin(tcb_calibration *out, tcb_error *err);

/* Where `calibrate` writes and the dry run reads a user's calibration:
 * $XDG_CONFIG_HOME/tcbench/calibration.json, else
 * $HOME/.config/tcbench/calibration.json; "" when neither is set. */
void tcb_calibration_user_path(char *out, size_t size);

/* The calibrations a dry run of run_dir reads, first match wins: the run
 * directory's calibration.json (one made on the nodes that run it), the
 * user's, the built-in defaults. A file that exists but does not parse is
 * an error naming it. */
#define TCB_CALIBRATION_SOURCES 3
typedef struct tcb_calibration_set {
    tcb_calibration c[TCB_CALIBRATION_SOURCES];
    int n;
} tcb_calibration_set;
int tcb_calibration_set_load(const char *run_dir, tcb_calibration_set *s, tcb_error *err);
void tcb_calibration_set_free(tcb_calibration_set *s);

/* The cost at `threads` from the first calibration that measured key (a
 * surface frame's per sample of a mesh): the measured value, else interpolated log-linearly in
 * the thread count between the nearest measured counts, else extrapolated
 * with the scaling of the last two (at best linear, never slower with more
 * threads; constant from a single count). */
typedef struct tcb_cost_price {
    double seconds;
    const tcb_calibration *from;
    int lo, hi;         /* the measured thread counts it derives from */
    int extrapolated;   /* threads outside [lo, hi] */
} tcb_cost_price;
typedef struct tcb_cost_key {
    tcb_cost_kind kind;
    const char *method, *preset, *unit; /* "" where the kind has none */
} tcb_cost_key;
int tcb_cost_lookup(const tcb_calibration_set *s, const tcb_cost_key *key, int threads, tcb_cost_price *out);

/* Prices a cell's estimate: one that named a preset with steps
 * (abi_version >= 5) gets fit_s = steps x the step cost (x the frames over
 * the calibration sequence's with step_frames) and eval_s from the pair
 * costs; its unit uses (abi_version >= 6) are added at their counts,
 * scaled with the vertex count's ratio to the calibration sequence's to
 * their exponent; a method with a surface (surface_samples > 0: the
 * config's samples per mesh) gets the reconstruction metrics of the frames
 * its pairs use added, or, not measured, a basis that says so; every
 * estimate with an eval_s gets the harness's scoring of q->n_pairs pairs
 * added, scaled with the square of the vertex count (the metrics compare
 * vertex with vertex; an upper bound). Unknown parts make fit_s and eval_s
 * -1, and basis says which command measures them. */
void tcb_cost_price_cell(const tcb_calibration_set *s, const char *method, const tcb_cost_query *q,
                         int surface_samples, tcb_cost_estimate *e);

/* ---- measuring (harness/step_timing.c) ---- */

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
 * distances) and the harness's scoring of its transfer. */
int tcb_time_eval_pairs(const tcb_method_ops *ops, void *self, const tcb_sequence *seq, int n, double *method_s,
                        double *score_s, tcb_error *err);

/* ---- the command (harness/calibrate.c) ---- */

typedef struct tcb_calibrate_opts {
    const int *threads;    /* thread counts to measure, increasing */
    int n_threads;
    const char *method;    /* NULL: every method with train_steps */
    const char *preset;    /* NULL: each of its presets */
    double budget_s;       /* the whole measurement's */
    int quick;             /* fewer steps and pairs: a coarse pass */
    int surface_samples;   /* per mesh, of the reconstruction metrics measured */
    const char *out_path;
} tcb_calibrate_opts;
int tcb_calibrate(const tcb_calibrate_opts *o, FILE *out, tcb_error *err);

#endif
