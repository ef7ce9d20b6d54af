/* Private to harness/: pieces shared by the config reader, the runner and
 * the CLI. Not installed, not part of the method ABI. */
#ifndef TCB_HARNESS_INTERNAL_H
#define TCB_HARNESS_INTERNAL_H

#include <stddef.h>

#include <cjson/cJSON.h>
#include <pthread.h>
#include <signal.h>
#include <stdatomic.h>

#include "tcb/config.h"
#include "tcb/geodesic.h"
#include "tcb/method.h"
#include "tcb/metrics.h"
#include "tcb/results.h"
#include "tcb/runner.h"
#include "tcb/sequence.h"
#include "tcb/split.h"

/* Value names of the config's enums, NULL-terminated; indexed by the enum. */
extern const char *const tcb_config_source_names[];   /* tcb_source */
extern const char *const tcb_config_norm_names[];     /* tcb_normalization */
extern const char *const tcb_config_protocol_names[]; /* by TCB_PROTOCOL_* bit position */
extern const char *const tcb_config_sampling_names[]; /* with_replacement: 0, 1 */

/* The config with every default filled in, pretty-printed; malloc'ed, NULL
 * when out of memory. (harness/config_dump.c) */
char *tcb_config_normalized_json(const tcb_config *c);

/* The chosen variant and the roots applied to a config's JSON tree before
 * it is read (harness/config_overlay.c). */
int tcb_config_apply_opts(cJSON *root, const char *origin, const tcb_config_opts *o, tcb_error *err);

/* Relative paths to code ("plugins", an external method's command) made
 * absolute against the directory of the config file `origin`; nothing
 * changes when origin names no file (harness/config_paths.c). */
int tcb_config_resolve_paths(cJSON *root, const char *origin, tcb_error *err);

/* <run_dir>/config.json, the record of the configs whose cells the
 * directory holds: created with cfg's normalized config when there is
 * none; else compared with cfg, and grown to the union of both (new
 * datasets, sequences, methods, seeds). A difference in a setting every
 * cell depends on is refused (TCB_ERR_INPUT, naming both configs, the key
 * path and both values) and nothing is written, unless opts->force, which
 * takes the directory over for cfg. A method of cfg whose "method" or
 * "params" differ from those recorded under its label is refused alone:
 * refused[k] = 1 for it (cfg->methods[k]) and `refusal` says why and how to
 * recompute it; the record keeps the old one. Under --force the selected
 * methods take cfg's settings instead. (harness/run_config.c) */
int tcb_run_dir_claim_methods(const tcb_config *cfg, const char *run_dir, const tcb_run_opts *opts,
                              unsigned char *refused, tcb_error *refusal, tcb_error *err);
/* The same for `tcbench score`, whose cell is no config method's: only a
 * setting every cell depends on is refused (`force`: taken over), with a
 * hint for score; differing methods keep their record. */
int tcb_run_dir_claim(const tcb_config *cfg, const char *run_dir, int force, tcb_error *err);

/* Pieces of the runner the dry run shares (harness/runner.c): */
/* the method is the one --only names, or every method without --only; */
int tcb_run_selected(const tcb_run_opts *opts, const tcb_method_spec *m);
/* the age past which a cell lock's holder no longer counts (--lock-timeout); */
double tcb_run_lock_timeout(const tcb_run_opts *opts);
/* every selected method exists and accepts its params; */
int tcb_run_check_methods(const tcb_config *cfg, const tcb_run_opts *opts, tcb_error *err);
/* d's data cannot be read: no root, or no such directory; */
int tcb_run_root_missing(const tcb_dataset_spec *d);
/* why: "no root given (--root NAME=DIR or TCBENCH_ROOT_NAME)" or "<root> not found". */
void tcb_run_missing_root_text(const tcb_dataset_spec *d, char *out, size_t size);
/* TCB_ERR_INPUT "<config>: dataset <name>: <why>" when d's data cannot be read. */
int tcb_run_check_root(const tcb_config *cfg, const tcb_dataset_spec *d, tcb_error *err);

/* The grid in cell-id order (harness/grid.c). */
typedef struct tcb_grid_cell {
    int id;
    const tcb_dataset_spec *dataset;
    const tcb_sequence_spec *sequence;
    const tcb_method_spec *method;
    int seed;
} tcb_grid_cell;
typedef int (*tcb_grid_visit)(void *ctx, const tcb_grid_cell *c);
int tcb_grid_for_each(const tcb_config *cfg, tcb_grid_visit visit, void *ctx); /* stops at a visit's error */
int tcb_grid_cells_per_sequence(const tcb_config *cfg, const tcb_dataset_spec *d);

/* Cell locks (harness/cell_lock.c): <cell>.json.lock, created atomically
 * with link(2), heartbeat = its mtime. */
typedef struct tcb_lock_info {
    int valid;                  /* the content parsed */
    char host[256];
    long pid;
    double started;             /* Unix time */
    double heartbeat_age_s;     /* now − mtime */
    char progress[160];         /* the holder's last progress ("mca 21000/40000"),
                                 * as of its last heartbeat; "" when none */
} tcb_lock_info;

typedef struct tcb_cell_lock {
    char path[TCB_PATH_MAX];
    int held, beating, stop;
    double timeout_s;
    pthread_t thread;           /* refreshes the heartbeat every timeout/4 */
    pthread_mutex_t mu;
    pthread_cond_t cv;
    char progress[160];         /* under mu: the cell's latest progress */
    int progress_new;           /* under mu: not yet in <lock>.progress */
} tcb_cell_lock;

/* Claims the cell at cell_path: l->held = 1 on success. When another live
 * process holds it, returns TCB_OK with l->held = 0 and the holder in
 * *holder; a stale lock is taken over and `note` says whose and why. */
int tcb_cell_lock_acquire(tcb_cell_lock *l, const char *cell_path, double timeout_s, tcb_lock_info *holder,
                          char *note, size_t note_size, tcb_error *err);
/* A reporter that notes progress in `lock` (each heartbeat writes the
 * latest into <lock>.progress, where `tcbench status` reads it; thread-safe)
 * and passes everything on to `inner`; `storage` holds both and must
 * outlive the reporter. */
typedef struct tcb_lock_reporter {
    tcb_cell_lock *lock;
    tcb_reporter inner;
} tcb_lock_reporter;
tcb_reporter tcb_lock_reporter_make(tcb_lock_reporter *storage, tcb_cell_lock *lock, const tcb_reporter *inner);
/* Stops the heartbeat and removes the lock (and its progress); nothing
 * when not held. */
void tcb_cell_lock_release(tcb_cell_lock *l);
/* The holder of the cell at cell_path: 0, or -1 when it has no lock. */
int tcb_cell_lock_holder(const char *cell_path, tcb_lock_info *info);
/* Why the holder no longer counts (its heartbeat is older than timeout_s,
 * or it was a process of this host that is gone): a run takes its lock
 * over. NULL while it counts. */
const char *tcb_cell_lock_stale_reason(const tcb_lock_info *h, double timeout_s);

/* The cells of a run directory that Slurm has queued (pending or running
 * array tasks submitted by scripts/slurm/submit.sh), from squeue
 * (harness/slurm_queue.c), asked only when submit.sh has left its mark
 * TCB_SLURM_MARK in the directory. Without squeue, the mark or the
 * directory, an empty queue; when squeue fails, an empty queue and a
 * one-line note. -1 only when out of memory. Free with tcb_slurm_queue_free. */
#define TCB_SLURM_MARK "slurm-submissions.log"
typedef struct tcb_slurm_queue {
    unsigned char *queued; /* [n_cells] 1: a queued task will run the cell */
    int n_cells;
    int asked;             /* squeue answered */
    char jobs[256];        /* the array job ids of those tasks, "57 58" */
} tcb_slurm_queue;
int tcb_slurm_queue_read(const char *run_dir, int n_cells, tcb_slurm_queue *q, char *note, size_t note_size);
void tcb_slurm_queue_free(tcb_slurm_queue *q);

/* SIGTERM / SIGUSR1 as a stop request (harness/stop_signals.c): start
 * blocks them in the calling thread (call it before any other thread
 * exists) and starts the thread that waits for them; requested() is the
 * signal received, 0 before one (a tcb_run_opts.interrupted); end restores
 * the mask. */
typedef struct tcb_stop_signals {
    sigset_t set, old;
    pthread_t thread;
    int started;
    atomic_int signal, closing;
} tcb_stop_signals;
int tcb_stop_signals_start(tcb_stop_signals *s);
int tcb_stop_signals_requested(const void *s);
void tcb_stop_signals_end(tcb_stop_signals *s);

/* Short git revision of the source tree tcbench was built from, or
 * "unknown". (harness/sysinfo.c) */
void tcb_git_revision(char *out, size_t size);
/* Peak resident set size of this process so far, in KiB. */
long tcb_peak_rss_kb(void);
/* The machine a calibration is made on, as JSON text (malloc'ed; NULL out
 * of memory): CPU model, cores, kernel, compiler, library versions,
 * tcbench's revision, the date and the load average; summary gets "CPU
 * model, N cores, load L" (the load average at the start). */
char *tcb_machine_describe(char *summary, size_t size);
/* The cores OpenMP may use. */
int tcb_cpu_count(void);

/* "synth/quadruped_walk/nearest/seed 0": how progress and logs name a cell.
 * The size fits the longest dataset, sequence and method names. */
#define TCB_CELL_LABEL_MAX 320
void tcb_cell_label(char *out, size_t size, const char *dataset, const char *sequence,
                    const char *method, int seed);

/* Loads the config's "plugins"; errors name the config and the entry.
 * (harness/runner.c) */
int tcb_harness_load_plugins(const tcb_config *cfg, tcb_error *err);

/* The sequence as the runner loads it for dataset d: generated or read
 * (through the cache; a cache entry refused is said to `reporter`, which
 * may be NULL), normalized, pools drawn, input settings set. On failure
 * *seq is freed and the message names dataset and sequence.
 * (harness/runner.c) */
int tcb_harness_load_sequence(const tcb_config *cfg, const tcb_dataset_spec *d, const char *name,
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
} tcb_cell_job;

/* The method of ops gives a surface per frame (tcb_method_ops.surface). */
static inline int tcb_method_has_surface(const tcb_method_ops *ops)
{
    return ops->abi_version >= 3 && ops->surface;
}

/* A method's failure rc that left merr empty described anyway, so the cell
 * fails with a readable message (harness/cell.c). */
void tcb_cell_ensure_error(tcb_error *merr, int rc);

/* What tcb/method.h promises of a method's surface of `frame` (at most
 * max_charts charts), checked before anything uses it; a failure lands in
 * merr (harness/surface_check.c). */
int tcb_surface_check(const tcb_uv_mesh *m, int frame, int max_charts, tcb_error *merr);

/* The reconstruction metrics of the cell's evaluated frames (every frame of
 * the split's pairs and of the clips, once each, ascending) into
 * c->surface and c->summary.recon, when the method gives surfaces and
 * job->surface_samples > 0 (harness/cell_surface.c). */
void tcb_cell_surface_metrics(const tcb_cell_job *job, void *self, tcb_cell_result *c, tcb_error *merr,
                              tcb_error *herr);

/* The record of a cell's model checkpoint (<checkpoint>.fit.json): the
 * cell it was made for, the sequence's fingerprint, the file's size and
 * hash, and the seconds the fit took (harness/model_record.c). Save
 * describes `saved`, the file about to be published as job->checkpoint;
 * check fails, naming the file and the reason, unless job->checkpoint is
 * that file and this cell's, and gives the recorded fit time. */
int tcb_model_record_save(const tcb_cell_job *job, const char *saved, double fit_s, tcb_error *err);
int tcb_model_record_check(const tcb_cell_job *job, double *fit_s, tcb_error *err);

/* A cell of a finished run picked by name, for `tcbench inspect` and
 * `tcbench frames` (harness/cell_target.c). */
typedef struct tcb_cell_target {
    const tcb_dataset_spec *d;
    const tcb_sequence_spec *s;
    const tcb_method_spec *m;
    const tcb_method_ops *ops;
    int seed;
} tcb_cell_target;

/* <run_dir>/config.json loaded with its plug-ins; an error names the file
 * ("... is not a run directory" when there is none). */
int tcb_run_config_open(const char *run_dir, tcb_config *cfg, tcb_error *err);
/* The cell of method label `method`, seed (< 0: the method's first) and
 * sequence "dataset/sequence" (NULL: the config's only one); every name the
 * config lacks is an error saying what it has. */
int tcb_cell_target_resolve(const tcb_config *cfg, const char *method, int seed, const char *sequence,
                            tcb_cell_target *t, tcb_error *err);

/* The target's sequence, split and paths, and a job that reopens its
 * fitted model (reuse and require the checkpoint: never refit a model that
 * saves). threads <= 0: the config's. */
typedef struct tcb_cell_session {
    tcb_sequence seq;
    tcb_split split;
    char split_path[TCB_PATH_MAX], work[TCB_PATH_MAX], ckpt[TCB_PATH_MAX];
    tcb_cell_job job;
} tcb_cell_session;
int tcb_cell_session_open(const tcb_config *cfg, const char *run_dir, const tcb_cell_target *t,
                          int threads, tcb_reporter reporter, tcb_cell_session *s, tcb_error *err);
void tcb_cell_session_close(tcb_cell_session *s);

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

/* The cell's identity from the job: names, method_impl (ops->name),
 * params, seed, split, git revision, load_s; status ok, empty summary.
 * (harness/cell.c) */
int tcb_cell_identity(const tcb_cell_job *job, tcb_cell_result *c, tcb_error *err);

/* Runs one cell into *out (status ok, failed or diverged). A method's error
 * is recorded in the cell, not returned: the return value is non-zero only
 * for harness failures (out of memory, metrics given bad input). Free *out
 * with tcb_cell_free. (harness/cell.c) */
int tcb_cell_run(const tcb_cell_job *job, tcb_cell_result *out, tcb_error *err);

/* One evaluation pair's prediction: a method's transfer, or what `tcbench
 * score` read from a file. */
typedef struct tcb_pair_prediction {
    int i, j;                 /* frames: source, target */
    const float *moved;       /* [n_verts][3] frame i's vertices carried onto frame j; NULL
                               * when pred already holds the ids */
    int32_t *pred;            /* [n_verts] the predicted vertex of frame j per vertex; the
                               * projection of moved is written here */
    double cd;                /* the pair's Chamfer distance; NaN without reconstructions */
    double *geo;              /* [n_verts] out: each vertex's normalised geodesic error; NULL
                               * when not wanted */
} tcb_pair_prediction;

/* What scoring a sequence's pairs needs beside the predictions: the
 * sequence, and the edge graph of its faces for the geodesic error
 * (tcb/geodesic.h), made once for all pairs since every frame shares the
 * faces. (harness/pair_score.c) */
typedef struct tcb_pair_scorer {
    const tcb_sequence *seq;
    tcb_edge_graph graph;
} tcb_pair_scorer;
int tcb_pair_scorer_init(tcb_pair_scorer *s, const tcb_sequence *seq, tcb_error *err);
void tcb_pair_scorer_free(tcb_pair_scorer *s);

/* The cell file's record of pair (i, j): its metrics (the geodesic ones
 * when m has them) and Chamfer distance (NaN: none). (harness/pair_score.c) */
tcb_pair_record tcb_pair_record_of(int i, int j, const tcb_pair_metrics *m, double cd);

/* Scores one pair: moved (when given) projected onto frame j's nearest GT
 * vertices, the metrics, the geodesic error among them (into *pm; may be
 * NULL), the cell file's record into *rec, and the pair added to *sum. The
 * one path from a prediction to a cell's numbers, for methods' cells and
 * scored cells alike, so a metric added here reaches both.
 * (harness/pair_score.c) */
int tcb_cell_score_pair(const tcb_pair_scorer *s, const tcb_pair_prediction *p, tcb_pair_record *rec,
                        tcb_summary *sum, tcb_pair_metrics *pm, tcb_error *err);

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

/* The prediction directory of `tcbench score` (tcb/score.h;
 * harness/score_files.c): dir holds 0.npy … <n_pairs-1>.npy and no <k>.npy
 * beyond (the split's path is for the messages). Errors name the file. */
int tcb_score_check_dir(const char *dir, int n_pairs, const char *split_path, tcb_error *err);

/* `tcbench datasets align`: the rotation alignment of an OBJ directory
 * (centred per frame) written as JSON to `out` and, with `plot`, as a PNG
 * of the yaw per frame; both atomically. (harness/align_cmd.c) */
typedef struct tcb_align_cmd {
    const char *out;   /* rotations.json */
    const char *plot;  /* NULL: no plot */
    int samples;       /* points per frame for the Chamfer */
    uint64_t seed;     /* of those samples */
} tcb_align_cmd;
int tcb_datasets_align(const char *dir, const tcb_align_cmd *a, tcb_error *err);

/* `tcbench datasets distortion`: the per-frame non-isometry of a synthetic
 * sequence (generated with seed and n_frames, ≤ 0: its default length) or
 * of an OBJ directory, as a table on out. (harness/distortion_cmd.c) */
int tcb_datasets_distortion(const char *what, uint64_t seed, int n_frames, FILE *out, tcb_error *err);

#endif
