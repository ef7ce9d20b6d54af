/* Private to reports/: renderers of the table model (reports/aggregate.h).
 * Text writers only print; the caller owns the stream, checks ferror and
 * publishes the file atomically. */
#ifndef TCB_REPORTS_WRITERS_H
#define TCB_REPORTS_WRITERS_H

#include <stdio.h>

#include "reports/aggregate.h"
#include "tcb/error.h"

void tcb_rpt_write_md(FILE *f, const tcb_rpt *r);   /* reports/table_md.c */
void tcb_rpt_write_tex(FILE *f, const tcb_rpt *r);  /* reports/table_tex.c */
void tcb_rpt_write_csv(FILE *f, const tcb_rpt *r);  /* reports/table_csv.c */
/* Names come from configs; escapes what LaTeX would read as markup. (reports/table_tex.c) */
void tcb_rpt_tex_escaped(FILE *f, const char *s);
/* by_gap.csv: each sequence row's m_sL2 per frame distance. (reports/table_csv.c) */
void tcb_rpt_write_gap_csv(FILE *f, const tcb_rpt *r);
/* seeds.csv: each cell's own means. (reports/table_csv.c) */
void tcb_rpt_write_seed_csv(FILE *f, const tcb_rpt *r);
/* A CSV field, quoted when it holds a comma, quote or newline. (reports/table_csv.c) */
void tcb_rpt_csv_field(FILE *f, const char *s);
/* comparisons.{md,tex,csv}: the blocks' pairwise differences, intervals and
 * Holm-adjusted p-values (needs a report built with statistics).
 * (reports/table_cmp.c) */
void tcb_rpt_write_cmp_md(FILE *f, const tcb_rpt *r);
void tcb_rpt_write_cmp_tex(FILE *f, const tcb_rpt *r);
void tcb_rpt_write_cmp_csv(FILE *f, const tcb_rpt *r);

/* The presets the run's rows name, "atlasnet `cpu`, mca `cpu`" (each
 * (row, preset) once); returns 1 when one of them is not `paper`. And the
 * sentence above a Markdown report's tables that says so (nothing when no
 * row names a preset). (reports/presets.c) */
#define TCB_RPT_PRESETS_MAX 1024
int tcb_rpt_presets(const tcb_rpt *r, char list[TCB_RPT_PRESETS_MAX]);
void tcb_rpt_write_presets_md(FILE *f, const tcb_rpt *r);

/* One PNG per block, published atomically at `path`: the PCK curves, the
 * geodesic PCK curves (reports/plot_pck.c) and m_sL2 by frame distance
 * (reports/plot_gap.c). */
int tcb_rpt_plot_pck(const tcb_rpt_block *b, const char *path, tcb_error *err);
int tcb_rpt_plot_pck_geo(const tcb_rpt_block *b, const char *path, tcb_error *err);
int tcb_rpt_plot_gap(const tcb_rpt_block *b, const char *path, tcb_error *err);

#endif
