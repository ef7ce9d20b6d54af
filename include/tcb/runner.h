/* tcbench — the grid runner: datasets × sequences × methods × seeds.
 *
 * For each cell: load (cached) sequence, obtain its split, create the method,
 * fit, transfer every evaluation pair, project, score, reconstruct when the
 * method can, and write the cell file atomically. Finished cells are skipped,
 * so rerunning a killed run resumes it and yields the same results. */
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
} tcb_run_opts;

typedef struct tcb_run_stats {
    int cells_total, cells_done, cells_skipped, cells_failed;
} tcb_run_stats;

int tcb_run(const tcb_config *cfg, const tcb_run_opts *opts, tcb_run_stats *stats,
            tcb_error *err);

/* The dry run: prints to `out` every cell (numbered in grid order over the
 * whole config), its state in the run directory and the compute it would
 * take, from each method's step costs; loads plug-ins and checks the
 * methods as tcb_run does, and runs nothing. */
int tcb_run_dry(const tcb_config *cfg, const tcb_run_opts *opts, FILE *out, tcb_error *err);

#ifdef __cplusplus
}
#endif
#endif
