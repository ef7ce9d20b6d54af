/* tcbench — reports and regression checks from a results directory.
 *
 * Tables are shaped like the paper's: one block per sequence, rows =
 * methods, columns m_sL2 ×1e3 ↓, rank % ↓, AUC % ↑, CD ×1e3 ↓ as mean ± std,
 * the best in bold when significantly best, else the leaders marked tied
 * (tcb/compare.h), "-" where a method has no reconstruction; a MEAN block per
 * dataset averages per-sequence means and stds over TEST sequences only
 * (reference-protocol §5.6). Cells of several seeds pool their pairs. */
#ifndef TCB_REPORT_H
#define TCB_REPORT_H

#include <stdio.h>

#include "tcb/error.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Writes <out_dir>/{tables.md, tables.tex, results.csv, by_gap.csv} and per
 * sequence pck_<dataset>_<sequence>.png and gap_<dataset>_<sequence>.png
 * (m_sL2 by frame distance |i − j|), out_dir NULL → <run>/report, and
 * echoes the Markdown tables to `echo` if non-NULL. */
int tcb_report_write(const char *run_dir, const char *out_dir, FILE *echo, tcb_error *err);
/* The same with `resamples` bootstrap resamples per comparison (0: the
 * default, TCB_BOOT_RESAMPLES = 10 000). Every report also writes
 * comparisons.{md,tex,csv} (tcb/compare.h: per sequence and metric, each
 * pair of methods' difference, 95 % interval and Holm-adjusted p), and
 * bolds a best value only when it is significantly better than every other
 * method, marking tied leaders otherwise (docs/protocol.md). */
int tcb_report_write_resampled(const char *run_dir, const char *out_dir, int resamples, FILE *echo,
                               tcb_error *err);

/* Our tables beside a reference's (the paper's numbers: `reference` is a
 * built-in name, "iccv21", or a tcbench-reference/1 file): the tables the
 * run's config names under "reference", else every table naming one of its
 * cells, in the paper's shape with ours, the paper's and ours/paper per
 * value and whether the methods' order agrees; writes
 * <out_dir>/reference_<name>.{md,tex,csv} (out_dir NULL: <run>/report) and
 * echoes the Markdown to `echo` if non-NULL. */
int tcb_report_reference(const char *run_dir, const char *reference, const char *out_dir, FILE *echo,
                         tcb_error *err);
/* The same with `resamples` per comparison (0: the default); each ordering
 * the paper makes is said to agree, flip significantly or flip within the
 * noise (the comparisons of tcb_report_write_resampled). */
int tcb_report_reference_resampled(const char *run_dir, const char *reference, const char *out_dir, int resamples,
                                   FILE *echo, tcb_error *err);

/* Baseline file "tcbench-baseline/1": per (dataset, sequence, method) the four
 * metrics in table units, plus per-metric tolerances. */
int tcb_baseline_write(const char *run_dir, const char *baseline_path, tcb_error *err);

/* Compare; prints a diff table to `out`; *n_drift = the baseline's rows
 * outside tolerance or missing from the run. The run's rows the baseline
 * does not name are listed as "not in the baseline" and never drift. */
int tcb_check(const char *run_dir, const char *baseline_path, FILE *out, int *n_drift,
              tcb_error *err);

/* A PNG of the yaw step[f] · 3° the rotation alignment chose per frame
 * (tcb/align.h), drawn in (−180°, 180°], written atomically. */
int tcb_plot_yaw(const char *path, const char *sequence, const int *step, int n_frames, int samples,
                 tcb_error *err);

#ifdef __cplusplus
}
#endif
#endif
