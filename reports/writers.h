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

/* pck_<dataset>_<sequence>.png, with characters outside [A-Za-z0-9._-] as '_'. */
int tcb_rpt_pck_name(const tcb_rpt_block *b, char *out, size_t size, tcb_error *err);
/* One PNG of the block's PCK curves, published atomically at `path`. (reports/plot_pck.c) */
int tcb_rpt_plot_pck(const tcb_rpt_block *b, const char *path, tcb_error *err);

#endif
