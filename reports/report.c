/* `tcbench report`: tables.md, tables.tex, results.csv and one PCK plot per
 * sequence, each published atomically. */
#include "tcb/report.h"

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

static int write_all(const tcb_rpt *r, const char *dir, tcb_error *err)
{
    int rc = tcb_mkdirs(dir, err);
    if (rc || (rc = write_text(dir, "tables.md", tcb_rpt_write_md, r, err)) ||
        (rc = write_text(dir, "tables.tex", tcb_rpt_write_tex, r, err)) ||
        (rc = write_text(dir, "results.csv", tcb_rpt_write_csv, r, err)))
        return rc;
    for (int k = 0; k < r->n_blocks; k++) {
        char name[TCB_PATH_MAX], path[TCB_PATH_MAX];
        if ((rc = tcb_rpt_pck_name(&r->blocks[k], name, sizeof name, err)) ||
            (rc = tcb_path_join(path, sizeof path, err, "%s/%s", dir, name)) ||
            (rc = tcb_rpt_plot_pck(&r->blocks[k], path, err)))
            return rc;
    }
    return TCB_OK;
}

int tcb_report_write(const char *run_dir, const char *out_dir, FILE *echo, tcb_error *err)
{
    char dir[TCB_PATH_MAX];
    int rc = out_dir ? tcb_path_join(dir, sizeof dir, err, "%s", out_dir)
                     : tcb_path_join(dir, sizeof dir, err, "%s/report", run_dir);
    if (rc) return rc;
    tcb_rpt r;
    if ((rc = tcb_rpt_load(run_dir, &r, err))) return rc;
    rc = write_all(&r, dir, err);
    if (!rc && echo) tcb_rpt_write_md(echo, &r);
    tcb_rpt_free(&r);
    return rc;
}
