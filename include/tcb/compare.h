/* tcbench — paired comparison of two methods from their cells (issue 27).
 *
 * On one (dataset, sequence): method A's ok cells (seeds) and method B's,
 * scored on the same split. Per metric — the report's columns m_sL2 ×1e3,
 * rank %, AUC %, CD ×1e3, m_geo ×1e3, AUC_geo %, in table units — each
 * pair's value (the pair's mean over its vertices for m_sL2, rank and
 * m_geo; its own value for AUC, CD and AUC_geo) gives, with
 * x_A[s][p] and x_B[s][p]:
 *   mean_a, mean_b  the mean over pairs of the seed-averaged values;
 *   diff            mean_a − mean_b (A − B, in table units);
 *   lo, hi          the 95 % interval of the seeded hierarchical paired
 *                   bootstrap (tcb/bootstrap.h: A's seeds, B's seeds, then
 *                   the pairs, the same for both), seed TCB_CMP_SEED, stream
 *                   "compare/<metric key>", TCB_BOOT_RESAMPLES resamples
 *                   unless told fewer;
 *   p               the two-sided Wilcoxon signed-rank p (tcb/wilcoxon.h, as
 *                   scipy.stats.wilcoxon) of the seed-averaged per-pair
 *                   differences; NaN when no test can be made (every
 *                   difference 0).
 * m_sL2 of a pair is the mean over its vertices, so mean_a is the table's
 * pooled m_sL2 when every pair has the same number of vertices (one mesh).
 *
 * The pairs are paired by position: both sides' cells must carry the same
 * split (path, seed) and the same (i, j) at every position (a split may
 * hold the same (i, j) twice); otherwise the comparison is refused. Corr
 * (the clip protocol's tracking error) is compared the same way over
 * clips instead of pairs: one value per clip, paired by position in the
 * same clip split (path, seed, starts); it is compared only when every
 * cell of both sides scored clips.
 *
 * With one seed on either side the seed level resamples nothing for it:
 * the interval then covers the sampling of pairs only, not the training
 * variance (single_seed is set, and every printout says so).
 *
 * Across sequences (a dataset's MEAN row): tcb_compare_means bootstraps the
 * sequences (each sequence's difference of the table's means is one "pair",
 * one seed per side) and tests them with Wilcoxon; with few sequences the
 * interval is rough (docs/protocol.md: the percentile interval covers
 * 80–92 % for 4–17 sequences) and Wilcoxon cannot reach p < 0.05 below six
 * sequences (exact test: its smallest two-sided p with n = 5 is 0.0625). */
#ifndef TCB_COMPARE_H
#define TCB_COMPARE_H

#include <stdio.h>

#include "tcb/error.h"
#include "tcb/results.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The bootstrap's seed: fixed, so that a report is reproducible. */
#define TCB_CMP_SEED 27u
/* A difference is significant when its adjusted p is below this and its
 * interval excludes 0. */
#define TCB_CMP_ALPHA 0.05

/* Metrics compared, in the report's column order. */
enum {
    TCB_CMP_SL2, TCB_CMP_RANK, TCB_CMP_AUC, TCB_CMP_CD, TCB_CMP_GEO, TCB_CMP_GEO_AUC,
    TCB_CMP_CORR, /* per clip of the clip protocol, not per pair */
    TCB_CMP_CORR_MESH, /* the same, DynoSurf's computation (methods with surfaces) */
    TCB_CMP_CDL2, TCB_CMP_NC, TCB_CMP_FSCORE05, TCB_CMP_FSCORE1, /* per evaluated frame */
    TCB_CMP_N_METRICS
};

typedef struct tcb_cmp_metric {
    int has;                 /* 0: a side has no value on some pair (no reconstruction,
                              * no geodesic error): nothing compared */
    double mean_a, mean_b;   /* table units */
    double diff, lo, hi;     /* A − B and its 95 % bootstrap interval */
    double p;                /* Wilcoxon, two-sided; NaN: no test (every difference 0) */
    double p_holm;           /* Holm-adjusted within the report's family; = p otherwise */
    int n;                   /* differences behind the test: pairs, clips, frames or sequences */
} tcb_cmp_metric;

typedef struct tcb_cmp {
    int seeds_a, seeds_b;    /* cells of each side (1 and 1 across sequences) */
    int n;                   /* pairs, or sequences when over_sequences */
    int n_clips;             /* clips behind Corr (0: Corr not compared) */
    int n_frames;            /* frames behind the reconstruction metrics (0: not compared) */
    int over_sequences;      /* a MEAN row: the sequences were resampled */
    int single_seed;         /* a side has one seed: training variance left out */
    int resamples;
    tcb_cmp_metric m[TCB_CMP_N_METRICS];
} tcb_cmp;

/* The comparison of A's cells a[0..na) with B's b[0..nb) (ok cells of one
 * (dataset, sequence), one per seed); resamples 0 → TCB_BOOT_RESAMPLES.
 * Errors (TCB_ERR_INPUT): no cell on a side, a cell not ok, cells of
 * another sequence, different splits or pair lists (naming both cells). */
int tcb_compare_cells(const tcb_cell_result *a, int na, const tcb_cell_result *b, int nb, int resamples,
                      tcb_cmp *out, tcb_error *err);

/* Across sequences: va[q], vb[q] are A's and B's table values of metric
 * `metric` on sequence q of n; fills out->m[metric] (has = 1) and the counts. */
int tcb_compare_means(const double *va, const double *vb, int n, int metric, int resamples, tcb_cmp *out,
                      tcb_error *err);

/* Significant at TCB_CMP_ALPHA by the adjusted p, interval excluding 0. */
int tcb_cmp_significant(const tcb_cmp_metric *m);

/* The metric's key ("sl2") and its label with units ("m_sL2 ×1e3"). */
const char *tcb_cmp_metric_key(int metric);
const char *tcb_cmp_metric_label(int metric);

/* `tcbench compare`: A and B of run_dir on (dataset, sequence), printed to
 * out. dataset NULL: the only dataset holding both labels; sequence NULL:
 * the only sequence holding both; sequence "MEAN": across the dataset's
 * test sequences. An unknown label, dataset or sequence is TCB_ERR_INPUT
 * naming it and what there is. */
int tcb_compare_run(const char *run_dir, const char *dataset, const char *sequence, const char *a, const char *b,
                    int resamples, FILE *out, tcb_error *err);

#ifdef __cplusplus
}
#endif
#endif
