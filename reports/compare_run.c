/* `tcbench compare RUN A B`: one comparison of two methods of a run, on a
 * sequence (over its pairs and seeds) or on a dataset's MEAN (over its test
 * sequences), printed with what its interval does and does not cover. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "reports/aggregate.h"
#include "tcb/bootstrap.h"
#include "tcb/compare.h"
#include "tcb/wilcoxon.h"

typedef struct target {
    const char *dataset, *sequence, *a, *b;
    char dataset_buf[64], sequence_buf[128];
} target;

static int has_method(const tcb_cell_result *c, int n, const char *dataset, const char *sequence, const char *m)
{
    for (int k = 0; k < n; k++)
        if ((!dataset || !strcmp(c[k].dataset, dataset)) && (!sequence || !strcmp(c[k].sequence, sequence)) &&
            !strcmp(c[k].method, m))
            return 1;
    return 0;
}

/* The run's distinct values of dataset (want 0) or sequence (want 1) where
 * both labels have cells, as "a, b" into list; their count. */
static int where_both(const tcb_cell_result *c, int n, const target *t, int want, char *list, size_t size,
                      const char **only)
{
    int count = 0;
    size_t used = 0;
    list[0] = '\0';
    for (int k = 0; k < n; k++) {
        const char *v = want ? c[k].sequence : c[k].dataset;
        if (want && strcmp(c[k].dataset, t->dataset)) continue;
        if (k && !strcmp(v, want ? c[k - 1].sequence : c[k - 1].dataset) &&
            (!want || !strcmp(c[k - 1].dataset, t->dataset)))
            continue;
        const char *ds = want ? t->dataset : v, *sq = want ? v : NULL;
        if (!has_method(c, n, ds, sq, t->a) || !has_method(c, n, ds, sq, t->b)) continue;
        if (!count++) *only = v;
        int w = snprintf(list + used, size - used, "%s%s", used ? ", " : "", v);
        if (w > 0 && (size_t)w < size - used) used += (size_t)w;
    }
    return count;
}

/* Dataset and sequence: given ("D/S" in --sequence too), or the only ones
 * holding both labels. */
static int resolve(const tcb_cell_result *c, int n, target *t, tcb_error *err)
{
    const char *slash = t->sequence ? strchr(t->sequence, '/') : NULL;
    if (slash) {
        snprintf(t->dataset_buf, sizeof t->dataset_buf, "%.*s", (int)(slash - t->sequence), t->sequence);
        t->dataset = t->dataset_buf, t->sequence = slash + 1;
    }
    for (int k = 0; k < 2; k++) {
        const char *label = k ? t->b : t->a;
        if (!has_method(c, n, NULL, NULL, label))
            return tcb_fail(err, TCB_ERR_INPUT, "compare: the run has no cell of method '%s'", label);
    }
    char list[512];
    const char *only = NULL;
    if (!t->dataset) {
        int count = where_both(c, n, t, 0, list, sizeof list, &only);
        if (count != 1)
            return tcb_fail(err, TCB_ERR_INPUT, "compare: %s and %s share %s: name one with --dataset%s%s",
                            t->a, t->b, count ? "several datasets" : "no dataset", count ? " (" : "",
                            count ? list : "");
        snprintf(t->dataset_buf, sizeof t->dataset_buf, "%s", only);
        t->dataset = t->dataset_buf;
    }
    int count = where_both(c, n, t, 1, list, sizeof list, &only);
    if (t->sequence && !strcmp(t->sequence, "MEAN")) return TCB_OK;
    if (t->sequence) {
        const char *missing = !has_method(c, n, t->dataset, t->sequence, t->a) ? t->a
                              : !has_method(c, n, t->dataset, t->sequence, t->b) ? t->b : NULL;
        if (!missing) return TCB_OK;
        return tcb_fail(err, TCB_ERR_INPUT, "compare: %s/%s: no cell of %s there (sequences of %s with both %s "
                        "and %s: %s; or MEAN)", t->dataset, t->sequence, missing, t->dataset, t->a, t->b,
                        count ? list : "none");
    }
    if (count != 1)
        return tcb_fail(err, TCB_ERR_INPUT, "compare: %s and %s share %d sequences of %s%s%s%s: name one with "
                        "--sequence (or MEAN)", t->a, t->b, count, t->dataset, count ? " (" : "", list,
                        count ? ")" : "");
    snprintf(t->sequence_buf, sizeof t->sequence_buf, "%s", only);
    t->sequence = t->sequence_buf;
    return TCB_OK;
}

/* The ok cells of method m on the target into out (pointers into c); cells
 * not ok are named on `f`. */
static int ok_cells(const tcb_cell_result *c, int n, const target *t, const char *m, tcb_cell_result *out,
                    FILE *f)
{
    int k = 0;
    for (int i = 0; i < n; i++) {
        if (strcmp(c[i].dataset, t->dataset) || strcmp(c[i].sequence, t->sequence) || strcmp(c[i].method, m))
            continue;
        if (c[i].status == TCB_CELL_OK) out[k++] = c[i];
        else fprintf(f, "left out: %s seed %d is %s\n", m, c[i].seed, tcb_cell_status_name(c[i].status));
    }
    return k;
}

/* Too few differences (the one or two clips behind a Corr) can never be
 * significant: "within noise" would claim a test that could not have been
 * made. */
static const char *verdict(const tcb_cmp *c, int metric, char *buf, size_t size)
{
    const tcb_cmp_metric *m = &c->m[metric];
    if (isnan(m->p)) return "no difference";
    if (tcb_wilcoxon_smallest_p(m->n) >= TCB_CMP_ALPHA) {
        snprintf(buf, size, "too few to test (%d)", m->n);
        return buf;
    }
    if (!tcb_cmp_significant(m)) return "within noise";
    int a_lower = m->diff < 0;
    return a_lower == tcb_rpt_metrics[metric].lower_is_better ? "A better (significant)" : "B better (significant)";
}

/* The metric's name padded to 16 columns: counted in characters, not bytes
 * ("×" is two bytes of UTF-8), so the numbers line up under each other. */
static void metric_label(FILE *f, const char *label)
{
    int width = 0;
    for (const unsigned char *c = (const unsigned char *)label; *c; c++) width += (*c & 0xc0) != 0x80;
    fprintf(f, "%s%*s", label, width < 16 ? 16 - width : 0, "");
}

static void print_result(FILE *f, const target *t, const tcb_cmp *c)
{
    fprintf(f, "A = %s, B = %s on %s/%s: %s\n", t->a, t->b, t->dataset, t->sequence,
            c->over_sequences ? "across the test sequences" : "paired over the split's pairs");
    if (c->over_sequences)
        fprintf(f, "%d sequence%s resampled (each one's difference of the table's means)%s\n", c->n,
                c->n == 1 ? "" : "s",
                c->n < 10 ? ": so few that the interval is rough (measured coverage of a 95 % interval: 80 % "
                            "with 4 sequences, 90 % with 10; docs/protocol.md)" : "");
    else
        fprintf(f, "%d pairs; seeds: A %d, B %d; bootstrap resamples A's seeds, B's seeds, then the pairs\n", c->n,
                c->seeds_a, c->seeds_b);
    if (!c->over_sequences && c->n_clips)
        fprintf(f, "Corr: paired over the %d clips of the clip split instead of the pairs\n", c->n_clips);
    if (!c->over_sequences && c->n_frames)
        fprintf(f, "CD-L2, NC, F-scores: paired over the %d evaluated frames instead of the pairs\n", c->n_frames);
    if (c->single_seed)
        fprintf(f, "note: %s one seed: the interval covers the sampling of pairs only, not the training "
                   "variance (another training may score differently)\n",
                c->seeds_a == 1 && c->seeds_b == 1 ? "each method has" : c->seeds_a == 1 ? "A has" : "B has");
    fprintf(f, "95 %% interval: percentile bootstrap, %d resamples, seed %u; p: two-sided Wilcoxon signed-rank on "
               "the %s differences, not adjusted (one comparison; a report's tables adjust with Holm)\n\n",
            c->resamples, TCB_CMP_SEED, c->over_sequences ? "per-sequence" : "seed-averaged per-pair");
    metric_label(f, "metric");
    fprintf(f, " %10s %10s %10s  %-22s %-9s %s\n", "A", "B", "A - B", "95 % interval", "p", "verdict");
    for (int m = 0; m < TCB_CMP_N_METRICS; m++) {
        const tcb_cmp_metric *x = &c->m[m];
        int d = tcb_rpt_metrics[m].decimals;
        if (!x->has) {
            metric_label(f, tcb_cmp_metric_label(m));
            fprintf(f, " %10s %10s %10s  %-22s %-9s %s\n", "-", "-", "-", "-", "-", "not compared: a side has no value");
            continue;
        }
        char iv[64], p[32], why[48];
        snprintf(iv, sizeof iv, "[%.*f, %.*f]", d + 1, x->lo, d + 1, x->hi);
        if (isnan(x->p)) snprintf(p, sizeof p, "no test");
        else snprintf(p, sizeof p, "%.2g", x->p);
        metric_label(f, tcb_cmp_metric_label(m));
        fprintf(f, " %10.*f %10.*f %10.*f  %-22s %-9s %s\n", d, x->mean_a, d, x->mean_b, d + 1, x->diff, iv, p,
                verdict(c, m, why, sizeof why));
    }
}

/* A's and B's MEAN rows of d as a two-row block (A then B), compared over
 * the test blocks tests[0..nt) as a report compares them. */
static int compare_mean_rows(const tcb_rpt_dataset *d, const target *t, const tcb_rpt_block *const *tests, int nt,
                             int resamples, tcb_cmp *out, tcb_error *err)
{
    const tcb_rpt_row *ra = NULL, *rb = NULL;
    for (int k = 0; k < d->mean.n_rows; k++) {
        if (!strcmp(d->mean.rows[k].method, t->a)) ra = &d->mean.rows[k];
        if (!strcmp(d->mean.rows[k].method, t->b)) rb = &d->mean.rows[k];
    }
    if (!ra || !rb)
        return tcb_fail(err, TCB_ERR_INPUT, "compare: %s has no cell on a test sequence of %s: no MEAN",
                        ra ? t->b : t->a, t->dataset);
    tcb_rpt_row two[2] = {*ra, *rb};
    tcb_rpt_block mb = {.n_rows = 2, .rows = two};
    int rc = tcb_rpt_compare_mean(&mb, tests, nt, resamples, err);
    if (!rc && mb.cmp[0].note[0])
        rc = tcb_fail(err, TCB_ERR_INPUT, "compare: MEAN of %s: %s", t->dataset, mb.cmp[0].note);
    if (!rc) *out = mb.cmp[0].c;
    free(mb.cmp);
    return rc;
}

/* Over the dataset's test sequences, from the table's per-sequence means. */
static int compare_mean(const tcb_cell_result *c, int n, const target *t, int resamples, tcb_cmp *out,
                        tcb_error *err)
{
    tcb_rpt r;
    int rc = tcb_rpt_build(c, n, TCB_RPT_NO_STATS, &r, err);
    if (rc) return rc;
    const tcb_rpt_dataset *d = &r.datasets[0]; /* resolve() made sure the dataset has cells */
    for (int k = 0; k < r.n_datasets; k++)
        if (!strcmp(r.datasets[k].name, t->dataset)) d = &r.datasets[k];
    const tcb_rpt_block **tests = malloc(sizeof *tests * (size_t)d->n);
    int nt = 0;
    if (!tests) rc = tcb_fail(err, TCB_ERR_NOMEM, "compare: out of memory");
    for (int k = 0; !rc && k < d->n; k++)
        if (!strcmp(r.blocks[d->first + k].role, "test")) tests[nt++] = &r.blocks[d->first + k];
    if (!rc && nt == 0) rc = tcb_fail(err, TCB_ERR_INPUT, "compare: %s has no test sequence: no MEAN", t->dataset);
    if (!rc) rc = compare_mean_rows(d, t, tests, nt, resamples, out, err);
    free(tests);
    tcb_rpt_free(&r);
    return rc;
}

static int compare_sequence(const tcb_cell_result *c, int n, const target *t, int resamples, FILE *f, tcb_cmp *out,
                            tcb_error *err)
{
    tcb_cell_result *a = malloc(sizeof *a * (size_t)n * 2), *b = a ? a + n : NULL;
    if (!a) return tcb_fail(err, TCB_ERR_NOMEM, "compare: out of memory");
    int na = ok_cells(c, n, t, t->a, a, f), nb = ok_cells(c, n, t, t->b, b, f);
    int rc = na && nb ? tcb_compare_cells(a, na, b, nb, resamples, out, err)
                      : tcb_fail(err, TCB_ERR_INPUT, "compare: %s/%s: %s has no ok cell", t->dataset, t->sequence,
                                 na ? t->b : t->a);
    free(a);
    return rc;
}

int tcb_compare_run(const char *run_dir, const char *dataset, const char *sequence, const char *a, const char *b,
                    int resamples, FILE *out, tcb_error *err)
{
    tcb_cell_result *cells;
    int n;
    int rc = tcb_results_scan(run_dir, &cells, &n, err);
    if (rc) return rc;
    target t = {dataset, sequence, a, b, "", ""};
    tcb_cmp c;
    if (!(rc = resolve(cells, n, &t, err)))
        rc = !strcmp(t.sequence, "MEAN") ? compare_mean(cells, n, &t, resamples, &c, err)
                                         : compare_sequence(cells, n, &t, resamples, out, &c, err);
    if (!rc) print_result(out, &t, &c);
    for (int k = 0; k < n; k++) tcb_cell_free(&cells[k]);
    free(cells);
    return rc;
}
