/* Private to harness/, the grid engine (harness/harness.h is its face): the
 * run directory's record, the grid, cell locks, the Slurm queue, and the
 * parts of running one cell that stay inside the engine. Not installed,
 * not part of the method ABI. */
#ifndef TCB_HARNESS_INTERNAL_H
#define TCB_HARNESS_INTERNAL_H

#include <stddef.h>

#include <pthread.h>

#include "harness/harness.h"
#include "tcb/results.h"
#include "tcb/runner.h"

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
/* The methods of cfg a run would refuse in run_dir (refused[k] = 1: their
 * "method", "params" or plug-in digest differ from the record), found
 * without writing anything, for `tcbench cells`; nothing is refused when
 * the directory has no record or an unreadable one. */
int tcb_run_dir_refusals(const tcb_config *cfg, const char *run_dir, const tcb_run_opts *opts,
                         unsigned char *refused, tcb_error *err);
/* The same for `tcbench score`, whose cell is no config method's: only a
 * setting every cell depends on is refused (`force`: taken over), with a
 * hint for score; differing methods keep their record. */
int tcb_run_dir_claim(const tcb_config *cfg, const char *run_dir, int force, tcb_error *err);

/* Pieces of the runner the dry run shares (harness/runner.c): */
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
/* The method is the one --only names, or every method without --only. */
int tcb_run_selected(const tcb_run_opts *opts, const tcb_method_spec *m);
/* "synth/quadruped_walk/nearest/seed 0": how progress, logs and model records
 * name a cell.
 * The size fits the longest dataset, sequence and method names. */
#define TCB_CELL_LABEL_MAX 320
void tcb_cell_label(char *out, size_t size, const char *dataset, const char *sequence,
                    const char *method, int seed);


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

/* A method's failure rc that left merr empty described anyway, so the cell
 * fails with a readable message (harness/cell.c). */
void tcb_cell_ensure_error(tcb_error *merr, int rc);

/* The method's surface of `frame` into *m (freed on failure), drawn from
 * the stream "surface/<dataset>/<sequence>/<frame>" of the cell's seed,
 * which *rng is left at, and checked (tcb_surface_check); failures are
 * the method's (harness/cell_surface.c). */
int tcb_cell_method_surface(const tcb_cell_job *job, void *self, int frame, tcb_rng *rng, tcb_uv_mesh *m,
                            tcb_error *merr);

/* DynoSurf's Corr of clip c of job->clips into rec->corr_mesh (NAN when the
 * method's surfaces change topology within the clip), for a method with
 * surfaces (harness/cell_corr_mesh.c). */
void tcb_cell_corr_mesh(const tcb_cell_job *job, void *self, int c, tcb_clip_record *rec, tcb_error *merr,
                        tcb_error *herr);

/* The two sample sets the reconstruction metrics of one frame score: the
 * method's surface and the GT mesh, in the frame job->recon_frame names
 * (gt_verts the GT frame's vertices in it; centre and scale the frame
 * box's map, identity otherwise), n samples each with unit normals. */
typedef struct tcb_surface_samples {
    int n;
    float *pred, *pred_n, *gt, *gt_n; /* [n][3] each */
    float *gt_verts;                  /* [n_verts][3] */
    double centre[3], scale;
} tcb_surface_samples;
int tcb_surface_samples_init(tcb_surface_samples *s, int n, int n_verts, tcb_error *herr);
void tcb_surface_samples_free(tcb_surface_samples *s);
/* Frame `frame`'s sample sets into s (sized by tcb_surface_samples_init):
 * the method's from the stream "surface/<dataset>/<sequence>/<frame>",
 * the GT's from "surface_gt/…" (harness/cell_surface.c). */
int tcb_cell_surface_samples(const tcb_cell_job *job, void *self, int frame, tcb_surface_samples *s,
                             tcb_error *merr, tcb_error *herr);

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

/* The cell's identity from the job: names, method_impl (ops->name),
 * params, seed, split, git revision, load_s; status ok, empty summary.
 * (harness/cell.c) */
int tcb_cell_identity(const tcb_cell_job *job, tcb_cell_result *c, tcb_error *err);

/* Runs one cell into *out (status ok, failed or diverged). A method's error
 * is recorded in the cell, not returned: the return value is non-zero only
 * for harness failures (out of memory, metrics given bad input). Free *out
 * with tcb_cell_free. (harness/cell.c) */
int tcb_cell_run(const tcb_cell_job *job, tcb_cell_result *out, tcb_error *err);

#endif
