/* `tcbench check`: a run's table rows against a baseline, as a fixed-width
 * diff table. A row the baseline names drifts when any of its values leaves
 * its tolerance, its status changed, or the run lacks it. A row the run has
 * and the baseline does not name (a method scored beside the shipped ones)
 * is listed as not in the baseline and never drifts: the baseline vouches
 * for its own rows only. A metric the baseline has no value for (the
 * geodesic error, in a baseline older than it) is listed as unchecked and
 * never drifts. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "reports/baseline.h"
#include "tcb/report.h"

typedef struct diff_table {
    FILE *out; /* NULL: count only */
    int row_w; /* width of the row-name column */
} diff_table;

static void line(const diff_table *t, const char *row, const char *metric, const char *base,
                 const char *cur, const char *delta, const char *tol, const char *result)
{
    if (t->out)
        fprintf(t->out, "%-*s  %-8s  %14s  %14s  %11s  %9s  %s\n", t->row_w, row, metric, base,
                cur, delta, tol, result);
}

static const char *verdict(int ok) { return ok ? "OK" : "DRIFT"; }
/* The result of a run's row that the baseline does not name. */
#define NOT_IN_BASELINE "not in the baseline"


/* One metric; returns 1 when within tolerance. */
static int check_value(const diff_table *t, const char *row, int m, const tcb_baseline_row *br,
                       const tcb_rpt_row *cr)
{
    char base[32] = "-", cur[32] = "-", delta[32] = "", tol[32] = "";
    if (br->has[m]) snprintf(base, sizeof base, "%.6f", br->value[m]);
    if (cr->has[m]) snprintf(cur, sizeof cur, "%.6f", cr->mean[m]);
    int ok = br->has[m] == cr->has[m];
    if (br->has[m] && cr->has[m]) {
        double d = cr->mean[m] - br->value[m];
        double limit = br->abs_tol[m] + br->rel_tol[m] * fabs(br->value[m]);
        snprintf(delta, sizeof delta, "%+.3e", d);
        snprintf(tol, sizeof tol, "%.1e", limit);
        ok = fabs(d) <= limit; /* false for NaN */
    }
    line(t, row, tcb_rpt_metrics[m].key, base, cur, delta, tol, verdict(ok));
    return ok;
}

/* One row present on both sides; returns 1 when it passes. */
static int check_row(const diff_table *t, const tcb_baseline_row *br, const tcb_rpt_row *cr)
{
    char row[320];
    snprintf(row, sizeof row, "%s/%s/%s", br->dataset, br->sequence, br->method);
    if (strcmp(br->status, cr->status) || strcmp(br->status, "ok")) {
        int ok = !strcmp(br->status, cr->status);
        line(t, row, "status", br->status, cr->status, "", "", verdict(ok));
        return ok;
    }
    int ok = 1;
    for (int m = 0; m < TCB_N_METRICS; m++) {
        if (br->checked[m]) {
            ok &= check_value(t, row, m, br, cr);
            continue;
        }
        /* A metric added since the baseline was written: shown, not judged.
         * When the run has no value for it either (Corr in a pairs-only run),
         * both sides agree there is nothing to compare. */
        if (!cr->has[m]) {
            line(t, row, tcb_rpt_metrics[m].key, "absent", "-", "", "", verdict(1));
            continue;
        }
        char cur[32];
        snprintf(cur, sizeof cur, "%.6f", cr->mean[m]);
        line(t, row, tcb_rpt_metrics[m].key, "absent", cur, "", "", "unchecked");
    }
    return ok;
}

static const tcb_rpt_row *find_current(const tcb_rpt *r, const tcb_baseline_row *br, int *flat)
{
    *flat = 0;
    for (int k = 0; k < r->n_blocks; k++) {
        const tcb_rpt_block *blk = &r->blocks[k];
        int match = !strcmp(blk->dataset, br->dataset) && !strcmp(blk->sequence, br->sequence);
        for (int i = 0; i < blk->n_rows; i++, (*flat)++)
            if (match && !strcmp(blk->rows[i].method, br->method)) return &blk->rows[i];
    }
    return NULL;
}

static int name_width(const tcb_rpt *r, const tcb_baseline *b)
{
    int w = 3;
    for (int k = 0; k < b->n_rows; k++) {
        int n = (int)(strlen(b->rows[k].dataset) + strlen(b->rows[k].sequence) +
                      strlen(b->rows[k].method) + 2);
        if (n > w) w = n;
    }
    for (int k = 0; k < r->n_blocks; k++)
        for (int i = 0; i < r->blocks[k].n_rows; i++) {
            int n = (int)(strlen(r->blocks[k].dataset) + strlen(r->blocks[k].sequence) +
                          strlen(r->blocks[k].rows[i].method) + 2);
            if (n > w) w = n;
        }
    return w;
}

static int compare(const tcb_rpt *r, const tcb_baseline *b, FILE *out, int *n_drift,
                   tcb_error *err)
{
    int n_cur = 0, n_missing = 0, n_extra = 0;
    for (int k = 0; k < r->n_blocks; k++) n_cur += r->blocks[k].n_rows;
    char *seen = calloc((size_t)n_cur + 1, 1);
    if (!seen) return tcb_fail(err, TCB_ERR_NOMEM, "check: out of memory");
    diff_table t = {out, name_width(r, b)};
    line(&t, "row", "metric", "baseline", "current", "delta", "tolerance", "result");
    for (int k = 0; k < b->n_rows; k++) {
        const tcb_baseline_row *br = &b->rows[k];
        int flat;
        const tcb_rpt_row *cr = find_current(r, br, &flat);
        if (!cr) {
            char row[320];
            snprintf(row, sizeof row, "%s/%s/%s", br->dataset, br->sequence, br->method);
            line(&t, row, "row", "present", "missing", "", "", verdict(0));
            n_missing++;
            continue;
        }
        seen[flat] = 1;
        *n_drift += !check_row(&t, br, cr);
    }
    int flat = 0;
    for (int k = 0; k < r->n_blocks; k++)
        for (int i = 0; i < r->blocks[k].n_rows; i++, flat++) {
            if (seen[flat]) continue;
            char row[320];
            snprintf(row, sizeof row, "%s/%s/%s", r->blocks[k].dataset, r->blocks[k].sequence,
                     r->blocks[k].rows[i].method);
            line(&t, row, "row", "absent", "present", "", "", NOT_IN_BASELINE);
            n_extra++;
        }
    free(seen);
    *n_drift += n_missing;
    if (out)
        fprintf(out, "\n%d baseline rows, %d current rows: %d drift (%d missing), %d not in the baseline\n",
            b->n_rows, n_cur, *n_drift, n_missing, n_extra);
    return TCB_OK;
}

int tcb_check(const char *run_dir, const char *baseline_path, FILE *out, int *n_drift,
              tcb_error *err)
{
    *n_drift = 0;
    tcb_baseline b;
    int rc = tcb_baseline_load(baseline_path, &b, err);
    if (rc) return rc;
    tcb_rpt r;
    if (!(rc = tcb_rpt_load(run_dir, &r, err))) {
        rc = compare(&r, &b, out, n_drift, err);
        tcb_rpt_free(&r);
    }
    tcb_baseline_free(&b);
    return rc;
}
