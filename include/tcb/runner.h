/* tcbench — the grid runner: datasets × sequences × methods × seeds.
 *
 * For each cell: load (cached) sequence, obtain its split, create the method,
 * fit, transfer every evaluation pair, project, score, reconstruct when the
 * method can, and write the cell file atomically. Finished cells are skipped,
 * so rerunning a killed run resumes it and yields the same results; failed
 * cells (no result) are computed again. A cell
 * is computed under its lock (<cell>.json.lock), so any number of processes
 * may run one config on one run directory and each cell is computed once. */
#ifndef TCB_RUNNER_H
#define TCB_RUNNER_H

#include <stdio.h>

#include "tcb/config.h"
#include "tcb/error.h"
#include "tcb/progress.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct tcb_run_opts {
    const char *output;      /* overrides config "output" when non-NULL */
    const char *only_method; /* run only this method label (NULL: all) */
    int force;               /* recompute finished cells */
    tcb_reporter reporter;
    const unsigned char *cells; /* [tcb_grid_count] 1: run cell id k; NULL: every cell */
    double lock_timeout_s;   /* a cell lock whose heartbeat is older is taken over; 0: 600 s */
    /* May be NULL. Nonzero: stop (a fit saves its state, the cell in hand is
     * released unwritten, no further cell starts) and return
     * TCB_ERR_INTERRUPTED. */
    int (*interrupted)(const void *arg);
    const void *interrupt_arg;
    int tasks;               /* tcb_run_dry: also the wall time of this many concurrent
                              * one-cell tasks (a Slurm array's); 0: not asked */
} tcb_run_opts;

#define TCB_LOCK_TIMEOUT_DEFAULT_S 600.0

/* The number of cells of the config, numbered 0.. in grid order (datasets,
 * sequences, methods, seeds): an id depends only on the config. */
int tcb_grid_count(const tcb_config *cfg);
/* mask[k] = 1 for the ids of spec ("3,5-7"), 0 for the others; errors name
 * the spec. */
int tcb_cell_set_parse(const char *spec, int n_cells, unsigned char *mask, tcb_error *err);
/* Keeps in mask only ids ≡ I mod N for spec "I/N", or for "auto" Slurm's
 * array task (SLURM_ARRAY_TASK_ID against SLURM_ARRAY_TASK_MIN/MAX or
 * SLURM_ARRAY_TASK_COUNT). */
int tcb_shard_parse(const char *spec, int n_cells, unsigned char *mask, tcb_error *err);

typedef struct tcb_run_stats {
    int cells_total, cells_done, cells_skipped;
    int cells_diverged;      /* of cells_done: a diverged training is the method's result */
    int cells_failed;        /* of cells_done: no result (a crash, a time-out, bad output); a rerun retries them */
    char *failures;          /* malloc'ed: "LABEL: MESSAGE\n" for each failed cell of this run, or NULL */
    int cells_busy;          /* locked by another live process: left to it */
    int refused;             /* the run directory refused some methods (tcb_run's error says which) */
} tcb_run_stats;

/* Runs the grid. A failed cell is recorded (status failed) and the run goes
 * on: it is counted in stats, not returned. A finished cell is skipped,
 * unless it failed: that one is computed again. When the run directory
 * refuses some methods' cells (their settings differ from those it holds
 * under their labels), the others are run and then that refusal is
 * returned (TCB_ERR_INPUT, stats->refused set). Free stats with
 * tcb_run_stats_free, whatever is returned. */
int tcb_run(const tcb_config *cfg, const tcb_run_opts *opts, tcb_run_stats *stats,
            tcb_error *err);
void tcb_run_stats_free(tcb_run_stats *stats);

/* The sequence `tcbench run` scores the cells of cfg's dataset and
 * sequence (both by name) on: generated or read (through the config's
 * cache), normalized, aligned, its pools drawn, its input settings set.
 * For code outside the runner that needs the very frames the cell files
 * were computed on (the Python binding's load_sequence). Errors name the
 * config and what is missing; on failure *out holds nothing. Free with
 * tcb_sequence_free. */
int tcb_run_load_sequence(const tcb_config *cfg, const char *dataset, const char *sequence, tcb_sequence *out,
                          tcb_error *err);

/* The dry run: prints to `out` every cell (numbered in grid order over the
 * whole config), its state in the run directory and the compute it would
 * take, from each method's step costs; loads plug-ins and checks the
 * methods as tcb_run does, and runs nothing. */
int tcb_run_dry(const tcb_config *cfg, const tcb_run_opts *opts, FILE *out, tcb_error *err);

/* `tcbench cells`: every cell of the config, in id order, with its state in
 * the run directory (done, failed, diverged, missing). */
int tcb_run_list_cells(const tcb_config *cfg, const tcb_run_opts *opts, FILE *out, tcb_error *err);

/* `tcbench status`: the running cells (host, pid, heartbeat age), the failed
 * ones with their messages, the count per state, and the missing ids as a
 * Slurm --array list ("0-3,7"). Cells that Slurm array tasks submitted for
 * this run directory will run (squeue, harness/slurm_queue.c) count as
 * queued and stay out of that list; squeue's failure is a warning through
 * opts->reporter. */
int tcb_run_status(const tcb_config *cfg, const tcb_run_opts *opts, FILE *out, tcb_error *err);

#ifdef __cplusplus
}
#endif
#endif
