/* Which differences of a table are real: every pair of a block's rows
 * compared (tcb/compare.h), Holm's adjustment over the block's comparisons
 * of one metric, and the best / tie marks.
 *
 * The Holm family: one block (a sequence, or a dataset's MEAN) and one
 * metric — every comparison of two ok rows that the block's matrix
 * (comparisons.{md,tex,csv}) reports for that metric, k(k − 1)/2 of them
 * for k rows; a comparison with no test (p NaN: every difference 0) is left
 * out of the family and counts as not significant.
 *
 * The marks, per block and metric, among the ok rows with a value (two at
 * least): the leader is the row with the best table value. It is "best"
 * (bold) when it is significantly better (tcb_cmp_significant, in its
 * favour) than every other row, the runner-up included; otherwise no row
 * is bold and the leader and every row not significantly worse than it
 * are marked as tied. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "reports/aggregate.h"
#include "tcb/wilcoxon.h"

const tcb_rpt_cmp *tcb_rpt_cmp_of(const tcb_rpt_block *b, int ra, int rb, int *flip)
{
    *flip = ra > rb;
    int lo = *flip ? rb : ra, hi = *flip ? ra : rb;
    for (int k = 0; k < b->n_cmp; k++)
        if (b->cmp[k].a == lo && b->cmp[k].b == hi) return b->cmp[k].note[0] ? NULL : &b->cmp[k];
    return NULL;
}

static int row_ok(const tcb_rpt_row *r) { return !strcmp(r->status, "ok"); }

/* Every pair (a < b) of the block's rows, in order; both ok or noted. */
static int alloc_pairs(tcb_rpt_block *b, tcb_error *err)
{
    int n = b->n_rows * (b->n_rows - 1) / 2;
    b->cmp = calloc(n > 0 ? (size_t)n : 1, sizeof *b->cmp);
    if (!b->cmp) return tcb_fail(err, TCB_ERR_NOMEM, "report: out of memory");
    for (int a = 0; a < b->n_rows; a++)
        for (int c = a + 1; c < b->n_rows; c++) {
            tcb_rpt_cmp *x = &b->cmp[b->n_cmp++];
            x->a = a, x->b = c;
            if (!row_ok(&b->rows[a]) || !row_ok(&b->rows[c]))
                snprintf(x->note, sizeof x->note, "%s is %s", b->rows[row_ok(&b->rows[a]) ? c : a].method,
                         b->rows[row_ok(&b->rows[a]) ? c : a].status);
        }
    b->compared = 1;
    return TCB_OK;
}

/* Holm over the block's tests of metric m; p_holm NaN where no test. */
static int holm_metric(tcb_rpt_block *b, int m, tcb_error *err)
{
    double *p = malloc(sizeof *p * (size_t)(b->n_cmp > 0 ? b->n_cmp : 1));
    if (!p) return tcb_fail(err, TCB_ERR_NOMEM, "report: out of memory");
    int n = 0;
    for (int k = 0; k < b->n_cmp; k++) {
        tcb_cmp_metric *c = &b->cmp[k].c.m[m];
        if (!b->cmp[k].note[0] && c->has && !isnan(c->p)) p[n++] = c->p;
    }
    int rc = tcb_holm_adjust(p, n, p, err);
    n = 0;
    for (int k = 0; k < b->n_cmp && !rc; k++) {
        tcb_cmp_metric *c = &b->cmp[k].c.m[m];
        c->p_holm = !b->cmp[k].note[0] && c->has && !isnan(c->p) ? p[n++] : NAN;
    }
    free(p);
    return rc;
}

int tcb_rpt_beats(const tcb_rpt_block *b, int r, int o, int m)
{
    int flip;
    const tcb_rpt_cmp *x = tcb_rpt_cmp_of(b, r, o, &flip);
    if (!x || !tcb_cmp_significant(&x->c.m[m])) return 0;
    double r_minus_o = flip ? -x->c.m[m].diff : x->c.m[m].diff;
    return tcb_rpt_metrics[m].lower_is_better ? r_minus_o < 0 : r_minus_o > 0;
}

static int candidate(const tcb_rpt_row *r, int m) { return row_ok(r) && r->has[m]; }

/* The rule of the file's comment, for metric m. */
static void mark_metric(tcb_rpt_block *b, int m)
{
    int lead = -1, n = 0;
    for (int k = 0; k < b->n_rows; k++) {
        tcb_rpt_row *r = &b->rows[k];
        r->best[m] = r->tie[m] = 0;
        if (!candidate(r, m)) continue;
        n++;
        double v = r->mean[m], lv = lead < 0 ? 0 : b->rows[lead].mean[m];
        if (lead < 0 || (tcb_rpt_metrics[m].lower_is_better ? v < lv : v > lv)) lead = k;
    }
    if (n < 2) return;
    int all = 1;
    for (int k = 0; k < b->n_rows; k++)
        if (k != lead && candidate(&b->rows[k], m)) all &= tcb_rpt_beats(b, lead, k, m);
    if (all) {
        b->rows[lead].best[m] = 1;
        return;
    }
    for (int k = 0; k < b->n_rows; k++)
        b->rows[k].tie[m] = candidate(&b->rows[k], m) && (k == lead || !tcb_rpt_beats(b, lead, k, m));
}

static int adjust_and_mark(tcb_rpt_block *b, tcb_error *err)
{
    for (int m = 0; m < TCB_N_METRICS; m++) {
        int rc = holm_metric(b, m, err);
        if (rc) return rc;
        mark_metric(b, m);
    }
    return TCB_OK;
}

/* cells[*first .. *end) hold method `name` (cells sorted by method). */
static void cells_of(const tcb_cell_result *cells, int n, const char *name, int *first, int *end)
{
    *first = 0;
    while (*first < n && strcmp(cells[*first].method, name)) (*first)++;
    *end = *first;
    while (*end < n && !strcmp(cells[*end].method, name)) (*end)++;
}

/* Comparison x of the block; cells that cannot be paired are said in its
 * note (the matrix shows it), not an error. */
static int compare_pair(const tcb_rpt_block *b, tcb_rpt_cmp *x, const tcb_cell_result *cells, int n,
                        int resamples, tcb_error *err)
{
    int fa, ea, fb, eb;
    cells_of(cells, n, b->rows[x->a].method, &fa, &ea);
    cells_of(cells, n, b->rows[x->b].method, &fb, &eb);
    int rc = tcb_compare_cells(cells + fa, ea - fa, cells + fb, eb - fb, resamples, &x->c, err);
    if (rc != TCB_ERR_INPUT) return rc;
    snprintf(x->note, sizeof x->note, "%s", err->msg);
    return TCB_OK;
}

/* The comparisons run in parallel: each draws its resamples afresh from
 * the comparison seed's streams (one per metric, reports/compare.c), so
 * the order they run in changes no bit of the report. The first failure in
 * comparison order is the one reported. */
int tcb_rpt_compare_block(tcb_rpt_block *b, const tcb_cell_result *cells, int n, int resamples,
                          tcb_error *err)
{
    int rc = alloc_pairs(b, err);
    if (rc) return rc;
    tcb_error *errs = calloc((size_t)(b->n_cmp > 0 ? b->n_cmp : 1), sizeof *errs);
    int *codes = calloc((size_t)(b->n_cmp > 0 ? b->n_cmp : 1), sizeof *codes);
    if (!errs || !codes) {
        free(errs), free(codes);
        return tcb_fail(err, TCB_ERR_NOMEM, "report: out of memory");
    }
#pragma omp parallel for schedule(dynamic)
    for (int k = 0; k < b->n_cmp; k++)
        if (!b->cmp[k].note[0]) codes[k] = compare_pair(b, &b->cmp[k], cells, n, resamples, &errs[k]);
    for (int k = 0; k < b->n_cmp && !rc; k++)
        if (codes[k]) rc = codes[k], *err = errs[k];
    free(errs), free(codes);
    return rc ? rc : adjust_and_mark(b, err);
}

/* Row `name`'s value of metric m in block t, or NaN. */
static double value_in(const tcb_rpt_block *t, const char *name, int m)
{
    for (int k = 0; k < t->n_rows; k++)
        if (!strcmp(t->rows[k].method, name)) return candidate(&t->rows[k], m) ? t->rows[k].mean[m] : NAN;
    return NAN;
}

/* Rows x->a and x->b of MEAN block mb over the test sequences, metric by metric. */
static int compare_over_sequences(const tcb_rpt_block *mb, tcb_rpt_cmp *x, const tcb_rpt_block *const *tests,
                                  int nt, int resamples, double *va, tcb_error *err)
{
    double *vb = va + nt;
    for (int m = 0; m < TCB_N_METRICS; m++) {
        int all = 1;
        for (int t = 0; t < nt; t++) {
            va[t] = value_in(tests[t], mb->rows[x->a].method, m);
            vb[t] = value_in(tests[t], mb->rows[x->b].method, m);
            all &= isfinite(va[t]) && isfinite(vb[t]);
        }
        int rc = all ? tcb_compare_means(va, vb, nt, m, resamples, &x->c, err) : TCB_OK;
        if (rc) return rc;
    }
    return TCB_OK;
}

int tcb_rpt_compare_mean(tcb_rpt_block *mb, const tcb_rpt_block *const *tests, int nt, int resamples,
                         tcb_error *err)
{
    int rc = alloc_pairs(mb, err);
    double *v = rc ? NULL : malloc(sizeof *v * 2 * (size_t)nt);
    if (!rc && !v) rc = tcb_fail(err, TCB_ERR_NOMEM, "report: out of memory");
    for (int k = 0; k < mb->n_cmp && !rc; k++)
        if (!mb->cmp[k].note[0]) rc = compare_over_sequences(mb, &mb->cmp[k], tests, nt, resamples, v, err);
    free(v);
    return rc ? rc : adjust_and_mark(mb, err);
}
