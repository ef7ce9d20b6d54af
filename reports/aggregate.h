/* Private to reports/: a run's cells folded into the table model that every
 * writer renders (Markdown, LaTeX, CSV, PCK plots, baseline, check).
 *
 * One block per (dataset, sequence), one row per method, seeds pooled with
 * tcb_summary_merge. Values are in table units (m_sL2 ×1e3, rank %, AUC %,
 * CD ×1e3, m_geo ×1e3, AUC_geo %). A row shows numbers only when every
 * pooled cell is "ok"; otherwise it carries the status, so a failure never
 * hides behind a number. The geodesic columns (tcb/geodesic.h, not the
 * paper's) show "-" unless every pooled pair has them: a cell written
 * before the geodesic error existed has none. Corr (×1e3, the clip
 * protocol's) shows "-" for cells that scored no clips; CD-L2 (×1e5), NC
 * and the F-scores (%) "-" for methods without surfaces and older cells. */
#ifndef TCB_REPORTS_AGGREGATE_H
#define TCB_REPORTS_AGGREGATE_H

#include <stddef.h>

#include "tcb/compare.h"
#include "tcb/error.h"
#include "tcb/metrics.h"
#include "tcb/results.h"

typedef enum tcb_rpt_metric {
    TCB_M_SL2,
    TCB_M_RANK,
    TCB_M_AUC,
    TCB_M_CD,
    TCB_M_GEO,      /* the geodesic error and its AUC: tcbench's addition */
    TCB_M_GEO_AUC,
    TCB_M_CORR,     /* the clip protocol's tracking error (DynoSurf/PDG/Neu-PiG), over clips */
    TCB_M_CORR_MESH, /* the same as DynoSurf's script computes it, from surfaces of one topology */
    TCB_M_CDL2,     /* the reconstruction metrics (tcb/metrics.h, TCB_RECON_* in this order), */
    TCB_M_NC,       /* over the evaluated frames of the methods that give surfaces */
    TCB_M_FSCORE05,
    TCB_M_FSCORE1,
    TCB_N_METRICS
} tcb_rpt_metric;

typedef struct tcb_rpt_metric_def {
    const char *key;       /* "sl2": baseline keys, CSV column stems */
    const char *label;     /* "m_sL2 ↓": Markdown header */
    const char *tex_label; /* LaTeX header */
    double scale;          /* raw value × scale = table units */
    int decimals;          /* printf precision in table units */
    int lower_is_better;
    int paper;             /* one of the paper's metrics; 0: an addition, which baselines
                            * and references written before it may lack */
} tcb_rpt_metric_def;

extern const tcb_rpt_metric_def tcb_rpt_metrics[TCB_N_METRICS];

/* One frame distance |i − j| of a row: how its error grows with the time
 * between the frames, which is what temporal coherence is about. */
typedef struct tcb_rpt_gap {
    int n_pairs;                      /* pairs at this distance, seeds pooled */
    tcb_stat sl2;                     /* per-vertex Euclidean error, raw units */
} tcb_rpt_gap;

/* One cell of a row, unpooled: how much the method's numbers move with the
 * seed, which the pooled mean ± std (over vertices and pairs) cannot show. */
typedef struct tcb_rpt_seed {
    int seed;
    const char *status;               /* the cell's status name */
    int n_pairs;
    int has[TCB_N_METRICS];           /* 0 → "-" (no reconstruction, or not ok) */
    int best[TCB_N_METRICS];          /* best among the block's cells of this seed */
    double mean[TCB_N_METRICS];       /* table units */
} tcb_rpt_seed;

typedef struct tcb_rpt_row {
    char method[64];
    char method_impl[64];             /* the registered method of its first cell */
    char params[256];                 /* that cell's params, compact JSON ("" when longer) */
    char normals[16];                 /* the normals its first cell's method took ("gt",
                                       * "estimated"; "" points only: tcb_cell_result.normals) */
    int no_faces;                     /* its first cell's sequence has no faces (MEAN rows:
                                       * the first test sequence's): tcb_cell_result.no_faces */
    const char *status;               /* "ok", "failed", "diverged" or "missing" */
    char status_text[64];             /* status plus how many pooled parts had it */
    char message[TCB_ERRMSG_MAX];     /* first failing cell: "seed 1: …" */
    int n_seeds;                      /* cells pooled (MEAN rows: the most of any sequence) */
    int n_pairs;                      /* pairs per cell (MEAN rows: sum over sequences) */
    int has[TCB_N_METRICS];           /* 0 → "-" (no reconstruction, or not ok) */
    int best[TCB_N_METRICS];          /* best of its block: as displayed without statistics;
                                       * with them, significantly better than every other
                                       * row (reports/significance.c) */
    int tie[TCB_N_METRICS];           /* with statistics: a leader not significantly apart
                                       * from the best (no row is then best) */
    double mean[TCB_N_METRICS];       /* table units */
    double std[TCB_N_METRICS];        /* table units */
    double sl2sq_mean, sl2sq_std;     /* ×1e3; valid when has[TCB_M_SL2] */
    double pck[TCB_PCK_STEPS];        /* percent; valid when status is "ok" */
    double geo_pck[TCB_GEO_PCK_STEPS]; /* percent; valid when has[TCB_M_GEO] */
    double geo_vertices;              /* vertices the geodesic error pooled */
    double geo_unreachable;           /* of them scored by the Euclidean fallback */
    int n_gaps;                       /* largest |i − j| + 1; 0 unless ok, and in MEAN rows */
    tcb_rpt_gap *by_gap;              /* malloc'ed [n_gaps], indexed by |i − j| */
    int n_by_seed;                    /* = n_seeds; 0 in MEAN rows */
    tcb_rpt_seed *by_seed;            /* malloc'ed [n_by_seed], ascending seed */
} tcb_rpt_row;

/* Two rows of a block compared (tcb/compare.h), a < b as row indices: a
 * minus b. Per sequence over pairs and seeds, in MEAN blocks over the test
 * sequences. p_holm is adjusted over the block's comparisons of one metric. */
typedef struct tcb_rpt_cmp {
    int a, b;
    char note[TCB_ERRMSG_MAX];        /* why not compared ("" when compared) */
    tcb_cmp c;                        /* c.m[m].has: metric m compared */
} tcb_rpt_cmp;

typedef struct tcb_rpt_block {
    char dataset[64];
    char sequence[128];               /* "MEAN" for a dataset mean block */
    char role[16];                    /* "train" | "validation" | "test" | "mean" */
    char seeds[128];                  /* distinct seeds, "0, 1" */
    int n_seed_list;                  /* the same as numbers; 0 in MEAN blocks */
    int *seed_list;                   /* malloc'ed [n_seed_list], ascending */
    int n_pairs_min, n_pairs_max;     /* over the block's rows */
    int n_rows;
    tcb_rpt_row *rows;                /* [n_rows], sorted by method */
    int compared;                     /* statistics made: cmp, best and tie as below */
    int n_cmp;
    tcb_rpt_cmp *cmp;                 /* malloc'ed [n_cmp]: every pair of rows, (0,1), (0,2)… */
} tcb_rpt_block;

typedef struct tcb_rpt_dataset {
    char name[64];
    int first, n;                     /* its blocks: blocks[first .. first + n) */
    int n_test;                       /* test sequences; 0 → no MEAN block */
    char test_sequences[512];         /* "horse, camel" */
    tcb_rpt_block mean;               /* valid when n_test > 0 */
} tcb_rpt_dataset;

typedef struct tcb_rpt {
    int n_blocks;
    tcb_rpt_block *blocks;            /* sorted by dataset, sequence */
    int n_datasets;
    tcb_rpt_dataset *datasets;
} tcb_rpt;

/* No statistics: best[] marks the displayed best (baselines, check). */
#define TCB_RPT_NO_STATS (-1)

/* cells sorted as tcb_results_scan returns them. resamples: the
 * comparisons' bootstrap resamples (0: TCB_BOOT_RESAMPLES), or
 * TCB_RPT_NO_STATS. */
int tcb_rpt_build(const tcb_cell_result *cells, int n, int resamples, tcb_rpt *out, tcb_error *err);
/* Scan <run>/cells and build without statistics; a run without cells is an error. */
int tcb_rpt_load(const char *run_dir, tcb_rpt *out, tcb_error *err);
/* The same with the comparisons (resamples as tcb_rpt_build). */
int tcb_rpt_load_compared(const char *run_dir, int resamples, tcb_rpt *out, tcb_error *err);

/* ---- statistics (reports/significance.c) ---- */

/* The block's rows compared pair by pair from its cells (those of
 * tcb_rpt_build's block), Holm per metric, then best and tie set by the
 * rule of docs/protocol.md. A pair whose cells cannot be paired (other
 * splits) is left uncompared with a note, not an error. */
int tcb_rpt_compare_block(tcb_rpt_block *b, const tcb_cell_result *cells, int n, int resamples,
                          tcb_error *err);
/* A MEAN block from the test blocks tests[0..nt): over sequences. */
int tcb_rpt_compare_mean(tcb_rpt_block *m, const tcb_rpt_block *const *tests, int nt, int resamples,
                         tcb_error *err);
/* The comparison of rows ra and rb of b (either order; *flip set when it is
 * rb − ra), NULL when not compared. */
const tcb_rpt_cmp *tcb_rpt_cmp_of(const tcb_rpt_block *b, int ra, int rb, int *flip);
/* Row r of b significantly better than its row o by metric m
 * (tcb_cmp_significant, the difference in r's favour). */
int tcb_rpt_beats(const tcb_rpt_block *b, int r, int o, int m);
void tcb_rpt_free(tcb_rpt *r);
/* Whether a table of dataset d shows metric m: some row of its blocks has
 * it (a pairs-only run has no Corr column, a clips-only run no m_sL2); when
 * no row has any number (every cell failed), the paper's four columns. */
int tcb_rpt_dataset_shows(const tcb_rpt *r, const tcb_rpt_dataset *d, int m);

/* One table cell: "mean<pm>std" in the metric's precision, "-" when the row
 * has no value, or the row's status when it is not ok (the tables explain
 * it below with status_text and message). */
void tcb_rpt_cell_text(const tcb_rpt_row *r, int metric, const char *pm, char *out,
                       size_t size);

#endif
