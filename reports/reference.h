/* Private to reports/: published numbers to set a run beside
 * (tcbench-reference/1, references/<name>.json, compiled into the library).
 *
 * A reference is a list of tables; each row is one number of the paper
 * with the table and row it came from and the cell of ours it compares
 * with: (dataset, sequence, method label), sequence "MEAN" for a dataset
 * mean row. Values are in table units (tcb_rpt_metrics) as [mean, std]. */
#ifndef TCB_REPORTS_REFERENCE_H
#define TCB_REPORTS_REFERENCE_H

#include "reports/aggregate.h"
#include "tcb/error.h"

#define TCB_REFERENCE_FORMAT "tcbench-reference/1"

typedef struct tcb_ref_row {
    char paper_row[96];            /* "AMA crane, delta 3": how the paper names it */
    char dataset[64], sequence[128], method[64];
    int has[TCB_N_METRICS];        /* 0: the paper gives no value */
    int has_std[TCB_N_METRICS];
    double mean[TCB_N_METRICS], std[TCB_N_METRICS];
} tcb_ref_row;

typedef struct tcb_ref_table {
    char id[16];                   /* "5" */
    char title[160];
    int n_rows;
    tcb_ref_row *rows;
} tcb_ref_table;

typedef struct tcb_reference {
    char name[32];
    char paper[320];
    int n_tables;
    tcb_ref_table *tables;
} tcb_reference;

/* `name` is a built-in reference ("iccv21") or the path of a file in the
 * format; errors name the file (or the built-in) and the key. */
int tcb_reference_load(const char *name, tcb_reference *out, tcb_error *err);
int tcb_reference_parse(const char *text, const char *origin, tcb_reference *out, tcb_error *err);
const tcb_ref_table *tcb_reference_table(const tcb_reference *r, const char *id);
void tcb_reference_free(tcb_reference *r);

/* The built-in references: NULL-terminated names and their JSON text
 * (reports/reference_builtin.c, generated from references/ by the build). */
extern const char *const tcb_reference_builtin_names[];
extern const char *const tcb_reference_builtin_texts[];

/* ---- a run beside a reference (reports/reference_compare.c) ---------- */

/* One row of a reference table and our cell for it (NULL: not run). */
typedef struct tcb_ref_cmp_row {
    const tcb_ref_row *paper;
    const tcb_rpt_row *ours;
    const tcb_rpt_block *block;      /* ours's block, and ours's index in it */
    int index;
} tcb_ref_cmp_row;

/* Rows of one (dataset, sequence) of a table: the methods the paper
 * compares there, in its order. */
typedef struct tcb_ref_group {
    const char *dataset, *sequence;
    int n_rows, n_ours;              /* n_ours: rows with a cell of ours */
    tcb_ref_cmp_row *rows;
} tcb_ref_group;

typedef struct tcb_ref_cmp_table {
    const tcb_ref_table *table;
    int shown[TCB_N_METRICS];        /* metrics the paper reports in this table */
    int n_groups;
    tcb_ref_group *groups;           /* only groups with at least one cell of ours */
    int n_absent;                    /* groups the run has no cell of */
} tcb_ref_cmp_table;

typedef struct tcb_ref_cmp {
    const tcb_reference *ref;
    const tcb_rpt *run;              /* the run set beside it */
    int n_tables;
    tcb_ref_cmp_table *tables;
} tcb_ref_cmp;

/* The tables `ids` of ref (n_ids 0: every table naming a cell of the run)
 * set beside run r; an unknown id is an error. */
int tcb_ref_compare(const tcb_reference *ref, const tcb_rpt *r, const char (*ids)[16], int n_ids, tcb_ref_cmp *out,
                    tcb_error *err);
void tcb_ref_cmp_free(tcb_ref_cmp *c);

/* How rows i and j of a group are ordered by metric m, here and in the
 * paper: not ordered (a value missing, or equal on either side), in the
 * same order, or the other way round — significantly (our comparison of
 * the two rows, Holm-adjusted within its block, is significant in our
 * order: reports/significance.c) or within the noise (not significant, or
 * not compared). *better_row gets the row the paper has better. */
typedef enum tcb_ref_order {
    TCB_REF_UNORDERED,
    TCB_REF_AGREES,
    TCB_REF_FLIPS_SIGNIFICANT,
    TCB_REF_FLIPS_NOISE
} tcb_ref_order;
tcb_ref_order tcb_ref_order_of(const tcb_ref_group *g, int i, int j, int m, int *better_row);

/* ours / paper of metric m's means; NaN when either is missing or the paper's is 0. */
double tcb_ref_ratio(const tcb_ref_cmp_row *row, int m);

/* Ours is far from the paper's when the ratio lies beyond TCB_REF_FAR
 * either way (above it, or below its inverse): the reports mark such a
 * cell, so a reader sees where a reduced preset or a deviation moved a
 * number, not only where it moved an ordering. */
#define TCB_REF_FAR 1.5
int tcb_ref_far(const tcb_ref_cmp_row *row, int m);

#endif
