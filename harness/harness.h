/* The face of harness/, the grid engine, for the rooms above it (views/,
 * the command line) and the tests: loading a cell's sequence, split and
 * plug-ins as `tcbench run` does, and running a method of one cell outside
 * a run (a job). The engine's own pieces are harness/harness_internal.h;
 * running a whole grid is tcb/runner.h. Not installed, not part of the
 * method ABI. */
#ifndef TCB_HARNESS_H
#define TCB_HARNESS_H

#include <stddef.h>
#include <stdint.h>

#include "tcb/config.h"
#include "tcb/method.h"
#include "tcb/metrics.h"
#include "tcb/split.h"

/* Loads the config's "plugins"; errors name the config and the entry.
 * (harness/runner.c) */
int tcb_harness_load_plugins(const tcb_config *cfg, tcb_error *err);

/* Sequence s of dataset d as the runner loads it: generated or read
 * (through the cache; a cache entry refused is said to `reporter`, which
 * may be NULL), normalized, pools drawn, input settings set; a clip of
 * another sequence (s->clip_of) cut out of it first. On failure *seq is
 * freed and the message names dataset and sequence. (harness/runner.c) */
int tcb_harness_load_sequence(const tcb_config *cfg, const tcb_dataset_spec *d, const tcb_sequence_spec *s,
                              const tcb_reporter *reporter, tcb_sequence *seq, tcb_error *err);
/* <splits_dir>/<dataset>/<sequence>.json: where the sequence's split lives. */
int tcb_harness_split_path(const tcb_config *cfg, const tcb_dataset_spec *d, const tcb_sequence_spec *s,
                           char *path, size_t size, tcb_error *err);
/* <splits_dir>/<dataset>/<sequence>.json into *split (made once, then
 * reused; a file made for other settings, frames or blocks than seq's is
 * refused, so every method sees the same pairs); its path in path[size]. */
int tcb_harness_obtain_split(const tcb_config *cfg, const tcb_dataset_spec *d,
                             const tcb_sequence_spec *s, const tcb_sequence *seq, char *path,
                             size_t size, tcb_split *split, tcb_error *err);
/* <splits_dir>/<dataset>/<sequence>.clips.json into *clips (the clip
 * protocol's start frames, tcb_clips_obtain; made once, then reused and
 * checked like the pairs' split); its path in path[size]. */
int tcb_harness_obtain_clips(const tcb_config *cfg, const tcb_dataset_spec *d,
                             const tcb_sequence_spec *s, const tcb_sequence *seq, char *path,
                             size_t size, tcb_split *clips, tcb_error *err);
/* A cell's work directory <run>/work/<dataset>/<sequence>/<label>/seed_<s>
 * and its model checkpoint <work>/model.ckpt, both [TCB_PATH_MAX]. */
int tcb_harness_work_paths(const char *run_dir, const char *dataset, const char *sequence,
                           const char *label, int seed, char *work, char *ckpt, tcb_error *err);

/* Everything one cell needs besides the method: the loaded sequence, its
 * split and where its files go. */
typedef struct tcb_cell_job {
    const tcb_sequence *seq;
    const tcb_split *split;
    const char *split_path;
    const tcb_dataset_spec *dataset;
    const tcb_method_spec *method;
    const tcb_method_ops *ops;
    int seed;
    int threads;
    int reuse_checkpoint;     /* load `checkpoint` when present instead of fitting */
    int require_checkpoint;   /* a method that saves must load `checkpoint`: never refit */
    const char *work_dir;     /* created by the caller */
    const char *checkpoint;   /* <work_dir>/model.ckpt, written after fit when ops->save */
    const char *git_revision;
    double load_s;            /* time spent loading the sequence */
    tcb_reporter reporter;
    int (*interrupted)(const void *arg); /* may be NULL: see tcb_fit_ctx */
    const void *interrupt_arg;
    /* The clip protocol's split, or NULL (no clips: a job that does not set
     * it). Without the pairs protocol, split->n_pairs is 0. */
    const tcb_split *clips;
    const char *clips_path;
    /* Samples per mesh of the reconstruction metrics ("evaluation.
     * surface_samples"); 0: not computed (a job that does not set it). */
    int surface_samples;
    /* The frame the reconstruction metrics are measured in ("evaluation.
     * recon_frame"; 0, the sequence's, in a job that does not set it). */
    tcb_recon_frame recon_frame;
} tcb_cell_job;

/* Creates job's method and loads (or, for methods without checkpoints,
 * fits) it with job->threads, hands it to use(ctx, self, merr) and destroys
 * it. A failure of the method or of `use` is an error prefixed with the
 * method's label. (harness/cell.c) */
typedef int (*tcb_method_use)(void *ctx, void *self, tcb_error *merr);
int tcb_cell_use_method(const tcb_cell_job *job, tcb_method_use use, void *ctx, tcb_error *err);

/* Tells a method of ABI >= 4 with prepare_pairs the pairs it will
 * transfer next, in order: pair m, numbered first + m, maps frame
 * pairs[2m] to pairs[2m + 1] (tcb/method.h). Nothing for other methods.
 * A failure is in merr, prefixed "prepare_pairs FIRST-LAST: ".
 * (harness/cell.c) */
int tcb_cell_prepare_pairs(const tcb_cell_job *job, void *self, const int *pairs, int first, int n,
                           tcb_error *merr);

/* One evaluation pair of a cell exactly as tcb_cell_run computes it (same
 * method state, random stream and projection), with what it produced. */
typedef struct tcb_pair_capture {
    int i, j;                 /* frames: source, target */
    float *moved;             /* [n_verts][3] the method's transfer of frame i's vertices */
    int32_t *pred;            /* [n_verts] predicted vertex ids of frame j */
    double *geo;              /* [n_verts] each vertex's normalised geodesic error */
    tcb_pair_metrics metrics;
    double cd;                /* NaN without reconstruct */
    float *recon[2];          /* [n_recon[f]][3] surface samples of frames i, j, or NULL */
    int n_recon[2];
} tcb_pair_capture;

/* Creates the method, loads (or, for methods without checkpoints, fits) it
 * and evaluates pair k of job->split into *out; a method's failure is an
 * error here, prefixed with its label. Free *out with tcb_pair_capture_free.
 * (harness/cell.c) */
int tcb_cell_eval_pair(const tcb_cell_job *job, int k, tcb_pair_capture *out, tcb_error *err);
void tcb_pair_capture_free(tcb_pair_capture *c);

#endif
