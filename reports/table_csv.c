/* results.csv: one row per (dataset, sequence, method), then each dataset's
 * MEAN rows (sequence "MEAN", role "mean"). Table units, the tables'
 * precision; empty fields where the tables show "-" or a status. The
 * geodesic columns come last (geo_unreachable: vertices scored by the
 * straight-line fallback, summed over the pooled pairs), then per metric
 * the mark (<key>_mark): "best" (significantly better than every other
 * row), "tie" (a leader tied for best) or empty (docs/protocol.md); Corr
 * before the marks, the reconstruction metrics (CD-L2, NC, F-scores) and
 * their marks after them: each addition at the end, so older readers'
 * columns stay put.
 *
 * by_gap.csv: one row per (dataset, sequence, method, frame distance) that
 * has pairs, for the methods whose cells are all ok.
 *
 * seeds.csv: one row per cell (dataset, sequence, method, seed), its own
 * means unpooled; empty fields where the cell has no value. */
#include <string.h>

#include "reports/writers.h"

void tcb_rpt_csv_field(FILE *f, const char *s)
{
    if (!strpbrk(s, ",\"\n")) {
        fputs(s, f);
        return;
    }
    fputc('"', f);
    for (; *s; s++) {
        if (*s == '"') fputc('"', f);
        fputc(*s, f);
    }
    fputc('"', f);
}

static void put_num(FILE *f, int has, double x, int decimals)
{
    if (has) fprintf(f, ",%.*f", decimals, x);
    else fputc(',', f);
}

static void put_block(FILE *f, const tcb_rpt_block *b, const tcb_rpt_row *r)
{
    tcb_rpt_csv_field(f, b->dataset);
    fputc(',', f);
    tcb_rpt_csv_field(f, b->sequence);
    fprintf(f, ",%s,", b->role);
    tcb_rpt_csv_field(f, r->method);
}

static void put_mean_std(FILE *f, const tcb_rpt_row *r, int m)
{
    put_num(f, r->has[m], r->mean[m], tcb_rpt_metrics[m].decimals);
    put_num(f, r->has[m], r->std[m], tcb_rpt_metrics[m].decimals);
}

static void put_marks(FILE *f, const tcb_rpt_row *r, int from, int to)
{
    for (int m = from; m < to; m++) fprintf(f, ",%s", r->best[m] ? "best" : r->tie[m] ? "tie" : "");
}

/* The paper's metrics and sL2² first, where they always were; the
 * additions (geodesic) after them, so older readers' columns stay put. */
static void write_row(FILE *f, const tcb_rpt_block *b, const tcb_rpt_row *r)
{
    put_block(f, b, r);
    fprintf(f, ",%s,%d,%d", r->status, r->n_seeds, r->n_pairs);
    for (int m = 0; m < TCB_N_METRICS; m++)
        if (tcb_rpt_metrics[m].paper) put_mean_std(f, r, m);
    /* sL2² is a squared distance like CD: same precision. */
    put_num(f, r->has[TCB_M_SL2], r->sl2sq_mean, tcb_rpt_metrics[TCB_M_CD].decimals);
    put_num(f, r->has[TCB_M_SL2], r->sl2sq_std, tcb_rpt_metrics[TCB_M_CD].decimals);
    for (int m = 0; m < TCB_M_CORR; m++)
        if (!tcb_rpt_metrics[m].paper) put_mean_std(f, r, m);
    put_num(f, r->has[TCB_M_GEO], r->geo_unreachable, 0);
    /* Corr, added after geo_unreachable, goes after it; then the marks; the
     * reconstruction metrics, added after the marks, after them with theirs. */
    put_mean_std(f, r, TCB_M_CORR);
    put_marks(f, r, 0, TCB_M_CORR + 1);
    for (int m = TCB_M_CDL2; m < TCB_N_METRICS; m++) put_mean_std(f, r, m);
    put_marks(f, r, TCB_M_CDL2, TCB_N_METRICS);
    /* DynoSurf's Corr, added after the reconstruction metrics, last. */
    put_mean_std(f, r, TCB_M_CORR_MESH);
    put_marks(f, r, TCB_M_CORR_MESH, TCB_M_CORR_MESH + 1);
    fputc('\n', f);
}

void tcb_rpt_write_csv(FILE *f, const tcb_rpt *r)
{
    fputs("dataset,sequence,role,method,status,seeds,n_pairs,sl2_x1e3_mean,sl2_x1e3_std,"
          "rank_pct_mean,rank_pct_std,auc_pct_mean,auc_pct_std,cd_x1e3_mean,cd_x1e3_std,"
          "sl2sq_x1e3_mean,sl2sq_x1e3_std,geo_x1e3_mean,geo_x1e3_std,geo_auc_pct_mean,"
          "geo_auc_pct_std,geo_unreachable,corr_x1e3_mean,corr_x1e3_std,sl2_mark,rank_mark,auc_mark,"
          "cd_mark,geo_mark,geo_auc_mark,corr_mark,cdl2_x1e5_mean,cdl2_x1e5_std,nc_pct_mean,nc_pct_std,"
          "fscore05_pct_mean,fscore05_pct_std,fscore1_pct_mean,fscore1_pct_std,cdl2_mark,nc_mark,fscore05_mark,"
          "fscore1_mark,corr_mesh_x1e3_mean,corr_mesh_x1e3_std,corr_mesh_mark\n",
          f);
    for (int d = 0; d < r->n_datasets; d++) {
        const tcb_rpt_dataset *ds = &r->datasets[d];
        for (int k = ds->first; k < ds->first + ds->n; k++)
            for (int i = 0; i < r->blocks[k].n_rows; i++)
                write_row(f, &r->blocks[k], &r->blocks[k].rows[i]);
        for (int i = 0; ds->n_test && i < ds->mean.n_rows; i++)
            write_row(f, &ds->mean, &ds->mean.rows[i]);
    }
}

void tcb_rpt_write_gap_csv(FILE *f, const tcb_rpt *r)
{
    const tcb_rpt_metric_def *d = &tcb_rpt_metrics[TCB_M_SL2];
    fputs("dataset,sequence,role,method,gap,n_pairs,n_vertices,sl2_x1e3_mean,sl2_x1e3_std\n", f);
    for (int k = 0; k < r->n_blocks; k++)
        for (int i = 0; i < r->blocks[k].n_rows; i++) {
            const tcb_rpt_row *row = &r->blocks[k].rows[i];
            for (int g = 0; g < row->n_gaps; g++) {
                const tcb_rpt_gap *gap = &row->by_gap[g];
                if (!gap->n_pairs) continue;
                put_block(f, &r->blocks[k], row);
                fprintf(f, ",%d,%d,%.0f,%.*f,%.*f\n", g, gap->n_pairs, gap->sl2.n, d->decimals,
                        gap->sl2.mean * d->scale, d->decimals, tcb_stat_std(&gap->sl2) * d->scale);
            }
        }
}

void tcb_rpt_write_seed_csv(FILE *f, const tcb_rpt *r)
{
    fputs("dataset,sequence,role,method,seed,status,n_pairs,sl2_x1e3_mean,rank_pct_mean,"
          "auc_pct_mean,cd_x1e3_mean,geo_x1e3_mean,geo_auc_pct_mean,corr_x1e3_mean,cdl2_x1e5_mean,nc_pct_mean,"
          "fscore05_pct_mean,fscore1_pct_mean,corr_mesh_x1e3_mean\n",
          f);
    for (int k = 0; k < r->n_blocks; k++)
        for (int i = 0; i < r->blocks[k].n_rows; i++) {
            const tcb_rpt_row *row = &r->blocks[k].rows[i];
            for (int j = 0; j < row->n_by_seed; j++) {
                const tcb_rpt_seed *s = &row->by_seed[j];
                put_block(f, &r->blocks[k], row);
                fprintf(f, ",%d,%s,%d", s->seed, s->status, s->n_pairs);
                /* every metric in the report's order, but corr_mesh, added later, last */
                for (int m = 0; m < TCB_N_METRICS; m++)
                    if (m != TCB_M_CORR_MESH) put_num(f, s->has[m], s->mean[m], tcb_rpt_metrics[m].decimals);
                put_num(f, s->has[TCB_M_CORR_MESH], s->mean[TCB_M_CORR_MESH], tcb_rpt_metrics[TCB_M_CORR_MESH].decimals);
                fputc('\n', f);
            }
        }
}
