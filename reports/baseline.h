/* Private to reports/: the regression baseline "tcbench-baseline/1".
 *
 *   { "format": "tcbench-baseline/1",
 *     "tolerances": { "sl2": {"abs", "rel"}, "rank": …, "auc": …, "cd": …,
 *                     "geo": …, "geo_auc": … },
 *     "rows": [ { "dataset", "sequence", "method",
 *                 "sl2", "rank", "auc", "cd",        table units; null = none
 *                 "geo", "geo_auc",                  the same, optional
 *                 "status",                          optional, "ok" by default
 *                 "tolerances" } ] }                 optional: the row's own, for
 *                                                    any of the metrics
 * The metrics that are not the paper's (the geodesic error) are optional
 * everywhere: a baseline written before them has none, and still checks
 * the paper's metrics as it did, leaving theirs unchecked; tolerances
 * missing for them default to DEFAULT_ABS_TOL and DEFAULT_REL_TOL.
 * A value passes when |current − baseline| ≤ abs + rel·|baseline|. Rows of
 * failed or diverged methods carry their status and null values. A row's
 * own tolerances (kept by hand: an --update writes the defaults) serve a
 * trained method whose last digits follow the CPU's BLAS kernels. */
#ifndef TCB_REPORTS_BASELINE_H
#define TCB_REPORTS_BASELINE_H

#include "reports/aggregate.h"

/* /2 from 2026-12-05: CD-L2 ×1e5 (the papers' scale). A /1 file, CD-L2
 * ×1e3, still loads: its CD-L2 values and absolute tolerances are scaled
 * by 100 as it is read. */
#define TCB_BASELINE_FORMAT "tcbench-baseline/2"
#define TCB_BASELINE_FORMAT_V1 "tcbench-baseline/1"

typedef struct tcb_baseline_row {
    char dataset[64];
    char sequence[128];
    char method[64];
    char status[16];             /* "ok" | "failed" | "diverged" */
    int checked[TCB_N_METRICS];  /* 0: not in the baseline (an optional metric left out) */
    int has[TCB_N_METRICS];      /* 0: null */
    double value[TCB_N_METRICS]; /* table units */
    double abs_tol[TCB_N_METRICS], rel_tol[TCB_N_METRICS]; /* the file's, or the row's own */
} tcb_baseline_row;

typedef struct tcb_baseline {
    double abs_tol[TCB_N_METRICS];
    double rel_tol[TCB_N_METRICS];
    int n_rows;
    tcb_baseline_row *rows;
} tcb_baseline;

int tcb_baseline_load(const char *path, tcb_baseline *out, tcb_error *err);
void tcb_baseline_free(tcb_baseline *b);

#endif
