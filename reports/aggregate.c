/* Cells → blocks of rows → per-dataset MEAN blocks (reference-protocol §5.6). */
#include "reports/aggregate.h"

#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

const tcb_rpt_metric_def tcb_rpt_metrics[TCB_N_METRICS] = {
    {"sl2", "m_sL2 ↓", "m\\_sL2 $\\downarrow$", 1e3, 2, 1, 1},
    {"rank", "rank ↓", "rank $\\downarrow$", 1e2, 2, 1, 1},
    {"auc", "AUC ↑", "AUC $\\uparrow$", 1e2, 2, 0, 1},
    /* %.3f as the authors' CSV: CD ×1e3 of good methods is ~0.09. */
    {"cd", "CD ↓", "CD $\\downarrow$", 1e3, 3, 1, 1},
    /* ×1e3 as m_sL2: a fraction of sqrt(area), good methods' ~0.01-0.05. */
    {"geo", "m_geo ↓", "m\\_geo $\\downarrow$", 1e3, 2, 1, 0},
    {"geo_auc", "AUC_geo ↑", "AUC\\_geo $\\uparrow$", 1e2, 2, 0, 0},
    /* ×1e3 as m_sL2 (the papers print it raw: their 0.010 is 10.00 here). */
    {"corr", "Corr ↓", "Corr $\\downarrow$", 1e3, 2, 1, 0},
    {"corr_mesh", "Corr-mesh ↓", "Corr-mesh $\\downarrow$", 1e3, 2, 1, 0},
    /* The reconstruction metrics: CD-L2 ×1e5 as the papers print it (their
     * 0.44 is 0.44 here), NC and F-score as percentages (the papers print
     * them raw: their 0.95 is 95.00 here). */
    {"cdl2", "CD-L2 ↓", "CD-L2 $\\downarrow$", 1e5, 2, 1, 0},
    {"nc", "NC ↑", "NC $\\uparrow$", 1e2, 2, 0, 0},
    {"fscore05", "F@0.5% ↑", "F@0.5\\% $\\uparrow$", 1e2, 2, 0, 0},
    {"fscore1", "F@1% ↑", "F@1\\% $\\uparrow$", 1e2, 2, 0, 0},
};
_Static_assert(TCB_M_FSCORE1 - TCB_M_CDL2 + 1 == TCB_N_RECON && TCB_M_FSCORE1 + 1 == TCB_N_METRICS,
               "the reconstruction columns are tcb/metrics.h's TCB_RECON_*, last");

static int same_block(const tcb_cell_result *a, const tcb_cell_result *b)
{
    return !strcmp(a->dataset, b->dataset) && !strcmp(a->sequence, b->sequence);
}

/* ------------------------------------------------------------ one row */

static void set_stat(tcb_rpt_row *r, int m, const tcb_stat *s)
{
    r->has[m] = s->n > 0;
    r->mean[m] = s->mean * tcb_rpt_metrics[m].scale;
    r->std[m] = tcb_stat_std(s) * tcb_rpt_metrics[m].scale;
}

static int gap_of(const tcb_pair_record *p) { return p->i > p->j ? p->i - p->j : p->j - p->i; }

/* The row's error by frame distance over its (ok) cells. */
static int build_gaps(const tcb_cell_result *cells, int n, tcb_rpt_row *r, tcb_error *err)
{
    int max_gap = -1;
    for (int k = 0; k < n; k++)
        for (int p = 0; p < cells[k].n_pairs; p++)
            if (gap_of(&cells[k].pairs[p]) > max_gap) max_gap = gap_of(&cells[k].pairs[p]);
    if (max_gap < 0) return TCB_OK;
    r->by_gap = calloc((size_t)max_gap + 1, sizeof *r->by_gap);
    if (!r->by_gap) return tcb_fail(err, TCB_ERR_NOMEM, "report: out of memory");
    r->n_gaps = max_gap + 1;
    for (int k = 0; k < n; k++)
        for (int p = 0; p < cells[k].n_pairs; p++) {
            tcb_rpt_gap *g = &r->by_gap[gap_of(&cells[k].pairs[p])];
            g->n_pairs++;
            tcb_stat_merge(&g->sl2, &cells[k].pairs[p].sl2);
        }
    return TCB_OK;
}

static void set_seed_stat(tcb_rpt_seed *s, int m, const tcb_stat *st)
{
    s->has[m] = st->n > 0;
    s->mean[m] = st->mean * tcb_rpt_metrics[m].scale;
}

/* Every pair of the summary has the geodesic error (none of an older cell,
 * or of a pooling with one, is shown rather than a part). */
static int all_geodesic(const tcb_summary *s)
{
    return s->n_pairs > 0 && s->geo_auc.n == s->n_pairs;
}

/* Each cell of the row on its own, failed ones included (as their status). */
static int build_seeds(const tcb_cell_result *cells, int n, tcb_rpt_row *r, tcb_error *err)
{
    r->by_seed = calloc((size_t)n, sizeof *r->by_seed);
    if (!r->by_seed) return tcb_fail(err, TCB_ERR_NOMEM, "report: out of memory");
    r->n_by_seed = n;
    for (int k = 0; k < n; k++) {
        const tcb_cell_result *c = &cells[k];
        tcb_rpt_seed *s = &r->by_seed[k];
        s->seed = c->seed;
        s->status = tcb_cell_status_name(c->status);
        s->n_pairs = c->n_pairs;
        if (c->status != TCB_CELL_OK) continue;
        set_seed_stat(s, TCB_M_SL2, &c->summary.sl2);
        set_seed_stat(s, TCB_M_RANK, &c->summary.rank);
        set_seed_stat(s, TCB_M_AUC, &c->summary.auc);
        set_seed_stat(s, TCB_M_CD, &c->summary.cd);
        set_seed_stat(s, TCB_M_CORR, &c->summary.corr);
        set_seed_stat(s, TCB_M_CORR_MESH, &c->summary.corr_mesh);
        for (int m = 0; m < TCB_N_RECON; m++) set_seed_stat(s, TCB_M_CDL2 + m, &c->summary.recon[m]);
        if (!all_geodesic(&c->summary)) continue;
        set_seed_stat(s, TCB_M_GEO, &c->summary.geo);
        set_seed_stat(s, TCB_M_GEO_AUC, &c->summary.geo_auc);
    }
    return TCB_OK;
}

static void set_geodesic(tcb_rpt_row *r, const tcb_summary *pooled)
{
    if (!all_geodesic(pooled)) return;
    set_stat(r, TCB_M_GEO, &pooled->geo);
    set_stat(r, TCB_M_GEO_AUC, &pooled->geo_auc);
    for (int s = 0; s < TCB_GEO_PCK_STEPS; s++) r->geo_pck[s] = pooled->geo_pck[s] * 100.0;
    r->geo_vertices = pooled->geo.n;
    r->geo_unreachable = pooled->geo_unreachable;
}

/* cells[0 .. n): one method of one block, ascending seeds. */
static int build_row(const tcb_cell_result *cells, int n, tcb_rpt_row *r, tcb_error *err)
{
    memset(r, 0, sizeof *r);
    snprintf(r->method, sizeof r->method, "%s", cells[0].method);
    snprintf(r->method_impl, sizeof r->method_impl, "%s", cells[0].method_impl);
    snprintf(r->normals, sizeof r->normals, "%s", cells[0].normals);
    r->no_faces = cells[0].no_faces;
    const char *params = cells[0].params_json ? cells[0].params_json : "";
    if (strlen(params) < sizeof r->params) memcpy(r->params, params, strlen(params) + 1);
    r->n_seeds = n;
    r->status = "ok";
    int rc = build_seeds(cells, n, r, err);
    if (rc) return rc;
    int n_bad = 0;
    tcb_summary pooled;
    tcb_summary_init(&pooled);
    for (int k = 0; k < n; k++) {
        const tcb_cell_result *c = &cells[k];
        if (c->n_pairs > r->n_pairs) r->n_pairs = c->n_pairs;
        if (c->status == TCB_CELL_OK) {
            tcb_summary_merge(&pooled, &c->summary);
        } else if (n_bad++ == 0) {
            r->status = tcb_cell_status_name(c->status);
            /* A message longer than the row's buffer ends in "..." */
            if (snprintf(r->message, sizeof r->message, "seed %d: %s", c->seed, c->message) >=
                (int)sizeof r->message)
                memcpy(r->message + sizeof r->message - 4, "...", 4);
        }
    }
    if (n_bad) {
        if (n_bad == n)
            snprintf(r->status_text, sizeof r->status_text, "%s", r->status);
        else
            snprintf(r->status_text, sizeof r->status_text, "%s (%d/%d seeds)", r->status, n_bad,
                     n);
        return TCB_OK;
    }
    snprintf(r->status_text, sizeof r->status_text, "ok");
    set_stat(r, TCB_M_SL2, &pooled.sl2);
    set_stat(r, TCB_M_RANK, &pooled.rank);
    set_stat(r, TCB_M_AUC, &pooled.auc);
    set_stat(r, TCB_M_CD, &pooled.cd);
    set_stat(r, TCB_M_CORR, &pooled.corr);
    set_stat(r, TCB_M_CORR_MESH, &pooled.corr_mesh);
    for (int m = 0; m < TCB_N_RECON; m++) set_stat(r, TCB_M_CDL2 + m, &pooled.recon[m]);
    r->sl2sq_mean = pooled.sl2sq.mean * 1e3;
    r->sl2sq_std = tcb_stat_std(&pooled.sl2sq) * 1e3;
    for (int s = 0; s < TCB_PCK_STEPS; s++) r->pck[s] = pooled.pck[s] * 100.0;
    set_geodesic(r, &pooled);
    return build_gaps(cells, n, r, err);
}

/* ------------------------------------------------------ best per column */

/* The value as printed, so that equal-looking numbers tie. */
static double displayed(double x, int decimals)
{
    char buf[64];
    snprintf(buf, sizeof buf, "%.*f", decimals, x);
    return strtod(buf, NULL);
}

/* Where a metric's values and best marks live: a row or one of its seeds. */
typedef struct candidate {
    const int *has;
    const double *mean;
    int *best;
} candidate;

/* Marks, per metric, every candidate whose displayed value is the best.
 * A value with nothing to compare against is no one's best: a seed only one
 * method ran on stays unmarked rather than bold in every column. */
static void mark_best(const candidate *c, int n)
{
    for (int m = 0; m < TCB_N_METRICS; m++) {
        const tcb_rpt_metric_def *d = &tcb_rpt_metrics[m];
        double best = d->lower_is_better ? INFINITY : -INFINITY;
        int compared = 0;
        for (int k = 0; k < n; k++) {
            if (!c[k].has[m]) continue;
            double v = displayed(c[k].mean[m], d->decimals);
            if (d->lower_is_better ? v < best : v > best) best = v;
            compared++;
        }
        for (int k = 0; k < n; k++)
            c[k].best[m] = compared > 1 && c[k].has[m] &&
                           displayed(c[k].mean[m], d->decimals) == best;
    }
}

/* The block's rows compared, then for each seed the rows' cells of it
 * (b->seed_list must be in place). */
static int mark_block_best(tcb_rpt_block *b, tcb_error *err)
{
    candidate *c = malloc(((size_t)b->n_rows + 1) * sizeof *c);
    if (!c) return tcb_fail(err, TCB_ERR_NOMEM, "report: out of memory");
    for (int k = 0; k < b->n_rows; k++)
        c[k] = (candidate){b->rows[k].has, b->rows[k].mean, b->rows[k].best};
    mark_best(c, b->n_rows);
    for (int d = 0; d < b->n_seed_list; d++) {
        int n = 0;
        for (int k = 0; k < b->n_rows; k++)
            for (int i = 0; i < b->rows[k].n_by_seed; i++) {
                tcb_rpt_seed *s = &b->rows[k].by_seed[i];
                if (s->seed == b->seed_list[d]) c[n++] = (candidate){s->has, s->mean, s->best};
            }
        mark_best(c, n);
    }
    free(c);
    return TCB_OK;
}

/* Pair-count range over the rows that scored pairs (a failed cell may have
 * none), and the best marks, once the rows are in place. */
static int finish_block(tcb_rpt_block *b, tcb_error *err)
{
    int any_ok = 0;
    for (int k = 0; k < b->n_rows; k++) any_ok |= !strcmp(b->rows[k].status, "ok");
    b->n_pairs_min = INT_MAX;
    b->n_pairs_max = 0;
    for (int k = 0; k < b->n_rows; k++) {
        const tcb_rpt_row *r = &b->rows[k];
        if (any_ok && strcmp(r->status, "ok")) continue;
        if (r->n_pairs < b->n_pairs_min) b->n_pairs_min = r->n_pairs;
        if (r->n_pairs > b->n_pairs_max) b->n_pairs_max = r->n_pairs;
    }
    return mark_block_best(b, err);
}

/* ----------------------------------------------------------- one block */

static int cmp_int(const void *a, const void *b)
{
    int x = *(const int *)a, y = *(const int *)b;
    return (x > y) - (x < y);
}

/* The block's distinct seeds, as a list and as the "0, 1" of its heading. */
static int block_seeds(const tcb_cell_result *cells, int n, tcb_rpt_block *b, tcb_error *err)
{
    b->seed_list = malloc((size_t)n * sizeof *b->seed_list);
    if (!b->seed_list) return tcb_fail(err, TCB_ERR_NOMEM, "report: out of memory");
    for (int k = 0; k < n; k++) b->seed_list[k] = cells[k].seed;
    qsort(b->seed_list, (size_t)n, sizeof *b->seed_list, cmp_int);
    for (int k = 0; k < n; k++)
        if (!b->n_seed_list || b->seed_list[k] != b->seed_list[b->n_seed_list - 1])
            b->seed_list[b->n_seed_list++] = b->seed_list[k];
    size_t used = 0;
    for (int k = 0; k < b->n_seed_list; k++) {
        int w = snprintf(b->seeds + used, sizeof b->seeds - used, "%s%d", used ? ", " : "",
                         b->seed_list[k]);
        if (w < 0 || (size_t)w >= sizeof b->seeds - used) {
            memcpy(b->seeds + sizeof b->seeds - sizeof ", …", ", …", sizeof ", …");
            break;
        }
        used += (size_t)w;
    }
    return TCB_OK;
}

/* cells[0 .. n): one (dataset, sequence), sorted by method then seed. */
static int build_block(const tcb_cell_result *cells, int n, int resamples, tcb_rpt_block *b, tcb_error *err)
{
    memset(b, 0, sizeof *b);
    snprintf(b->dataset, sizeof b->dataset, "%s", cells[0].dataset);
    snprintf(b->sequence, sizeof b->sequence, "%s", cells[0].sequence);
    snprintf(b->role, sizeof b->role, "%s", cells[0].role);
    for (int k = 1; k < n; k++)
        if (strcmp(cells[k].role, b->role))
            return tcb_fail(err, TCB_ERR_INPUT,
                            "cells of %s/%s disagree on the role: %s (%s) vs %s (%s seed %d)",
                            b->dataset, b->sequence, b->role, cells[0].method, cells[k].role,
                            cells[k].method, cells[k].seed);
    b->rows = calloc((size_t)n, sizeof *b->rows);
    if (!b->rows) return tcb_fail(err, TCB_ERR_NOMEM, "report: out of memory");
    for (int k = 0; k < n;) {
        int e = k + 1;
        while (e < n && !strcmp(cells[e].method, cells[k].method)) e++;
        int rc = build_row(cells + k, e - k, &b->rows[b->n_rows++], err);
        if (rc) return rc;
        k = e;
    }
    int rc = block_seeds(cells, n, b, err);
    if (!rc) rc = finish_block(b, err);
    if (!rc && resamples != TCB_RPT_NO_STATS) rc = tcb_rpt_compare_block(b, cells, n, resamples, err);
    return rc;
}

/* ------------------------------------------------------ MEAN of a dataset */

static const tcb_rpt_row *find_row(const tcb_rpt_block *b, const char *method)
{
    for (int k = 0; k < b->n_rows; k++)
        if (!strcmp(b->rows[k].method, method)) return &b->rows[k];
    return NULL;
}

/* The mean over the test blocks `tests[0 .. nt)` of one method's per-sequence
 * means, and separately of its per-sequence stds (§5.6). */
static void mean_row(const tcb_rpt_block *const *tests, int nt, const char *method,
                     tcb_rpt_row *r)
{
    memset(r, 0, sizeof *r);
    snprintf(r->method, sizeof r->method, "%s", method);
    r->status = "ok";
    int n_bad = 0;
    for (int t = 0; t < nt; t++) {
        const tcb_rpt_row *s = find_row(tests[t], method);
        const char *st = s ? s->status : "missing";
        if (strcmp(st, "ok") && n_bad++ == 0) {
            r->status = st;
            snprintf(r->message, sizeof r->message, "%.127s: %.880s", tests[t]->sequence,
                     s ? s->message : "no cell");
        }
    }
    if (n_bad) {
        snprintf(r->status_text, sizeof r->status_text, "%s (%d/%d test sequences)", r->status,
                 n_bad, nt);
        return;
    }
    snprintf(r->status_text, sizeof r->status_text, "ok");
    for (int m = 0; m < TCB_N_METRICS; m++) r->has[m] = 1;
    for (int t = 0; t < nt; t++) {
        const tcb_rpt_row *s = find_row(tests[t], method);
        if (s->n_seeds > r->n_seeds) r->n_seeds = s->n_seeds;
        if (t == 0) memcpy(r->method_impl, s->method_impl, sizeof r->method_impl);
        if (t == 0) memcpy(r->params, s->params, sizeof r->params);
        if (t == 0) memcpy(r->normals, s->normals, sizeof r->normals);
        if (t == 0) r->no_faces = s->no_faces;
        r->n_pairs += s->n_pairs;
        for (int m = 0; m < TCB_N_METRICS; m++) {
            r->has[m] &= s->has[m];
            r->mean[m] += s->mean[m] / nt;
            r->std[m] += s->std[m] / nt;
        }
        r->sl2sq_mean += s->sl2sq_mean / nt;
        r->sl2sq_std += s->sl2sq_std / nt;
        for (int k = 0; k < TCB_PCK_STEPS; k++) r->pck[k] += s->pck[k] / nt;
        for (int k = 0; k < TCB_GEO_PCK_STEPS; k++) r->geo_pck[k] += s->geo_pck[k] / nt;
        r->geo_vertices += s->geo_vertices;
        r->geo_unreachable += s->geo_unreachable;
    }
}

static int cmp_row(const void *a, const void *b)
{
    return strcmp(((const tcb_rpt_row *)a)->method, ((const tcb_rpt_row *)b)->method);
}

static int build_mean(tcb_rpt *r, tcb_rpt_dataset *d, int resamples, tcb_error *err)
{
    const tcb_rpt_block **tests = malloc((size_t)d->n * sizeof *tests);
    if (!tests) return tcb_fail(err, TCB_ERR_NOMEM, "report: out of memory");
    int nt = 0, max_rows = 0;
    size_t used = 0;
    for (int k = d->first; k < d->first + d->n; k++) {
        const tcb_rpt_block *b = &r->blocks[k];
        if (strcmp(b->role, "test")) continue;
        tests[nt++] = b;
        max_rows += b->n_rows;
        int w = snprintf(d->test_sequences + used, sizeof d->test_sequences - used, "%s%s",
                         used ? ", " : "", b->sequence);
        if (w > 0 && (size_t)w < sizeof d->test_sequences - used) used += (size_t)w;
    }
    d->n_test = nt;
    if (!nt) {
        free(tests);
        return TCB_OK;
    }
    tcb_rpt_block *m = &d->mean;
    snprintf(m->dataset, sizeof m->dataset, "%s", d->name);
    snprintf(m->sequence, sizeof m->sequence, "MEAN");
    snprintf(m->role, sizeof m->role, "mean");
    m->rows = calloc((size_t)max_rows, sizeof *m->rows);
    if (!m->rows) {
        free(tests);
        return tcb_fail(err, TCB_ERR_NOMEM, "report: out of memory");
    }
    /* Methods: the union over test sequences; one absent somewhere is "missing". */
    for (int t = 0; t < nt; t++)
        for (int k = 0; k < tests[t]->n_rows; k++) {
            const char *name = tests[t]->rows[k].method;
            if (!find_row(m, name))
                mean_row(tests, nt, name, &m->rows[m->n_rows++]);
        }
    qsort(m->rows, (size_t)m->n_rows, sizeof *m->rows, cmp_row);
    snprintf(m->seeds, sizeof m->seeds, "%s", tests[0]->seeds);
    int rc = finish_block(m, err);
    if (!rc && resamples != TCB_RPT_NO_STATS) rc = tcb_rpt_compare_mean(m, tests, nt, resamples, err);
    free(tests);
    return rc;
}

/* --------------------------------------------------------------- the run */

static int build_datasets(tcb_rpt *r, int resamples, tcb_error *err)
{
    r->datasets = calloc((size_t)r->n_blocks, sizeof *r->datasets);
    if (!r->datasets) return tcb_fail(err, TCB_ERR_NOMEM, "report: out of memory");
    for (int k = 0; k < r->n_blocks;) {
        tcb_rpt_dataset *d = &r->datasets[r->n_datasets++];
        snprintf(d->name, sizeof d->name, "%s", r->blocks[k].dataset);
        d->first = k;
        while (k < r->n_blocks && !strcmp(r->blocks[k].dataset, d->name)) k++;
        d->n = k - d->first;
        int rc = build_mean(r, d, resamples, err);
        if (rc) return rc;
    }
    return TCB_OK;
}

int tcb_rpt_build(const tcb_cell_result *cells, int n, int resamples, tcb_rpt *out, tcb_error *err)
{
    memset(out, 0, sizeof *out);
    if (n <= 0) return TCB_OK;
    out->blocks = calloc((size_t)n, sizeof *out->blocks);
    if (!out->blocks) return tcb_fail(err, TCB_ERR_NOMEM, "report: out of memory");
    int rc = TCB_OK;
    for (int k = 0; k < n && !rc;) {
        int e = k + 1;
        while (e < n && same_block(&cells[k], &cells[e])) e++;
        rc = build_block(cells + k, e - k, resamples, &out->blocks[out->n_blocks++], err);
        k = e;
    }
    if (!rc) rc = build_datasets(out, resamples, err);
    if (rc) tcb_rpt_free(out);
    return rc;
}

int tcb_rpt_load(const char *run_dir, tcb_rpt *out, tcb_error *err)
{
    return tcb_rpt_load_compared(run_dir, TCB_RPT_NO_STATS, out, err);
}

int tcb_rpt_load_compared(const char *run_dir, int resamples, tcb_rpt *out, tcb_error *err)
{
    memset(out, 0, sizeof *out);
    tcb_cell_result *cells;
    int n;
    int rc = tcb_results_scan(run_dir, &cells, &n, err);
    if (rc) return rc;
    if (n == 0)
        rc = tcb_fail(err, TCB_ERR_INPUT, "%s/cells: no cell files: nothing to report", run_dir);
    else
        rc = tcb_rpt_build(cells, n, resamples, out, err);
    for (int k = 0; k < n; k++) tcb_cell_free(&cells[k]);
    free(cells);
    return rc;
}

void tcb_rpt_free(tcb_rpt *r)
{
    for (int k = 0; k < r->n_blocks; k++) {
        for (int i = 0; i < r->blocks[k].n_rows; i++) {
            free(r->blocks[k].rows[i].by_gap);
            free(r->blocks[k].rows[i].by_seed);
        }
        free(r->blocks[k].rows);
        free(r->blocks[k].seed_list);
        free(r->blocks[k].cmp);
    }
    for (int k = 0; k < r->n_datasets; k++) {
        free(r->datasets[k].mean.rows);
        free(r->datasets[k].mean.cmp);
    }
    free(r->blocks);
    free(r->datasets);
    memset(r, 0, sizeof *r);
}

void tcb_rpt_cell_text(const tcb_rpt_row *r, int metric, const char *pm, char *out, size_t size)
{
    const tcb_rpt_metric_def *d = &tcb_rpt_metrics[metric];
    if (strcmp(r->status, "ok"))
        snprintf(out, size, "%s", r->status);
    else if (!r->has[metric])
        snprintf(out, size, "-");
    else
        snprintf(out, size, "%.*f%s%.*f", d->decimals, r->mean[metric], pm, d->decimals,
                 r->std[metric]);
}

static int dataset_has(const tcb_rpt *r, const tcb_rpt_dataset *d, int m)
{
    for (int k = d->first; k < d->first + d->n; k++)
        for (int i = 0; i < r->blocks[k].n_rows; i++)
            if (r->blocks[k].rows[i].has[m]) return 1;
    return 0;
}

int tcb_rpt_dataset_shows(const tcb_rpt *r, const tcb_rpt_dataset *d, int m)
{
    if (dataset_has(r, d, m)) return 1;
    /* no row with any number (every cell failed): the paper's columns, for
     * the rows' statuses to stand in */
    for (int o = 0; o < TCB_N_METRICS; o++)
        if (dataset_has(r, d, o)) return 0;
    return tcb_rpt_metrics[m].paper;
}
