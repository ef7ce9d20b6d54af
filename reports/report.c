/* `tcbench report`: tables.md, tables.tex, results.csv, by_gap.csv, seeds.csv,
 * comparisons.md, comparisons.tex, comparisons.csv and three
 * plots per sequence (PCK, geodesic PCK, m_sL2 by frame distance), each
 * published atomically. */
#include "tcb/report.h"

#include "reports/chart.h"
#include "reports/writers.h"
#include "tcb/fsutil.h"

typedef void (*text_writer)(FILE *f, const tcb_rpt *r);

static int write_text(const char *dir, const char *name, text_writer w, const tcb_rpt *r,
                      tcb_error *err)
{
    char path[TCB_PATH_MAX];
    tcb_atomic_file af;
    int rc = tcb_path_join(path, sizeof path, err, "%s/%s", dir, name);
    if (rc || (rc = tcb_atomic_open(&af, path, err))) return rc;
    w(af.fp, r);
    return tcb_atomic_commit(&af, err);
}

typedef int (*block_plot)(const tcb_rpt_block *b, const char *path, tcb_error *err);

static int write_plot(const char *dir, const char *prefix, block_plot plot,
                      const tcb_rpt_block *b, tcb_error *err)
{
    char name[TCB_PATH_MAX], path[TCB_PATH_MAX];
    int rc = tcb_chart_file_name(b, prefix, name, sizeof name, err);
    if (rc || (rc = tcb_path_join(path, sizeof path, err, "%s/%s", dir, name))) return rc;
    return plot(b, path, err);
}

static int write_all(const tcb_rpt *r, const char *dir, tcb_error *err)
{
    int rc = tcb_mkdirs(dir, err);
    if (rc || (rc = write_text(dir, "tables.md", tcb_rpt_write_md, r, err)) ||
        (rc = write_text(dir, "tables.tex", tcb_rpt_write_tex, r, err)) ||
        (rc = write_text(dir, "results.csv", tcb_rpt_write_csv, r, err)) ||
        (rc = write_text(dir, "by_gap.csv", tcb_rpt_write_gap_csv, r, err)) ||
        (rc = write_text(dir, "seeds.csv", tcb_rpt_write_seed_csv, r, err)) ||
        (rc = write_text(dir, "comparisons.md", tcb_rpt_write_cmp_md, r, err)) ||
        (rc = write_text(dir, "comparisons.tex", tcb_rpt_write_cmp_tex, r, err)) ||
        (rc = write_text(dir, "comparisons.csv", tcb_rpt_write_cmp_csv, r, err)))
        return rc;
    /* the plots are of pairs: a block of clips alone has none to draw */
    for (int k = 0; k < r->n_blocks && !rc; k++)
        if (r->blocks[k].n_pairs_max > 0 && !(rc = write_plot(dir, "pck", tcb_rpt_plot_pck, &r->blocks[k], err)) &&
            !(rc = write_plot(dir, "pck_geo", tcb_rpt_plot_pck_geo, &r->blocks[k], err)))
            rc = write_plot(dir, "gap", tcb_rpt_plot_gap, &r->blocks[k], err);
    return rc;
}

int tcb_report_write(const char *run_dir, const char *out_dir, FILE *echo, tcb_error *err)
{
    return tcb_report_write_resampled(run_dir, out_dir, 0, echo, err);
}

int tcb_report_write_resampled(const char *run_dir, const char *out_dir, int resamples, FILE *echo,
                               tcb_error *err)
{
    char dir[TCB_PATH_MAX];
    int rc = out_dir ? tcb_path_join(dir, sizeof dir, err, "%s", out_dir)
                     : tcb_path_join(dir, sizeof dir, err, "%s/report", run_dir);
    if (rc) return rc;
    tcb_rpt r;
    if ((rc = tcb_rpt_load_compared(run_dir, resamples, &r, err))) return rc;
    rc = write_all(&r, dir, err);
    if (!rc && echo) tcb_rpt_write_md(echo, &r);
    tcb_rpt_free(&r);
    return rc;
}
