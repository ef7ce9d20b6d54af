/* Paired comparison of two methods' cells (tcb/compare.h): the per-pair
 * values of each metric, the hierarchical bootstrap of their mean
 * difference and the Wilcoxon test of the seed-averaged differences. */
#include "tcb/compare.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "reports/aggregate.h"
#include "tcb/bootstrap.h"
#include "tcb/wilcoxon.h"

_Static_assert((int)TCB_CMP_N_METRICS == (int)TCB_N_METRICS, "compare.h's metrics are the report's columns");
_Static_assert((int)TCB_CMP_SL2 == (int)TCB_M_SL2 && (int)TCB_CMP_CD == (int)TCB_M_CD && (int)TCB_CMP_CORR == (int)TCB_M_CORR &&
                   (int)TCB_CMP_CORR_MESH == (int)TCB_M_CORR_MESH &&
                   (int)TCB_CMP_CDL2 == (int)TCB_M_CDL2 && (int)TCB_CMP_FSCORE1 == (int)TCB_M_FSCORE1 &&
                   (int)TCB_CMP_GEO_AUC == (int)TCB_M_GEO_AUC,
               "compare.h's metrics are in the report's column order");

const char *tcb_cmp_metric_key(int metric) { return tcb_rpt_metrics[metric].key; }

const char *tcb_cmp_metric_label(int metric)
{
    static const char *const labels[TCB_CMP_N_METRICS] = {"m_sL2 ×1e3", "rank %",     "AUC %",   "CD ×1e3",
                                                          "m_geo ×1e3", "AUC_geo %", "Corr ×1e3",
                                                          "Corr-mesh ×1e3", "CD-L2 ×1e5", "NC %",      "F@0.5% %", "F@1% %"};
    return labels[metric];
}

int tcb_cmp_significant(const tcb_cmp_metric *m)
{
    return m->has && m->p_holm < TCB_CMP_ALPHA && (m->lo > 0 || m->hi < 0);
}

/* Pair p's raw value of metric m; NaN when the pair has none. */
static double pair_value(const tcb_pair_record *p, int m)
{
    switch (m) {
    case TCB_M_SL2: return p->sl2.n > 0 ? p->sl2.mean : NAN;
    case TCB_M_RANK: return p->rank.n > 0 ? p->rank.mean : NAN;
    case TCB_M_AUC: return p->auc;
    case TCB_M_CD: return p->cd;
    case TCB_M_GEO: return p->geo.n > 0 ? p->geo.mean : NAN;
    default: return p->geo.n > 0 ? p->geo_auc : NAN;
    }
}

static int is_recon(int m) { return m >= TCB_M_CDL2 && m <= TCB_M_FSCORE1; }

/* The units metric m is paired over: clips for Corr, evaluated frames for
 * the reconstruction metrics, else pairs. */
static int units(const tcb_cell_result *c, int m)
{
    return m == TCB_M_CORR || m == TCB_M_CORR_MESH ? c->n_clips : is_recon(m) ? c->n_surface : c->n_pairs;
}

static double unit_value(const tcb_cell_result *c, int u, int m)
{
    if (is_recon(m)) return c->surface[u].v[m - TCB_M_CDL2];
    if (m == TCB_M_CORR_MESH) return c->clips[u].corr_mesh;
    return m == TCB_M_CORR ? c->clips[u].corr : pair_value(&c->pairs[u], m);
}

/* Unit u of c is unit u of first: the same frame (pairs and clips are
 * checked with the split). */
static int same_unit(const tcb_cell_result *c, const tcb_cell_result *first, int u, int m)
{
    return !is_recon(m) || c->surface[u].frame == first->surface[u].frame;
}

/* Cells c[0..n) of metric m into x[s][u] in table units over the units
 * of `first` (their count); 0 when a cell has other units or a value is
 * missing (the metric is then not compared). */
static int fill(const tcb_cell_result *c, int n, int m, const tcb_cell_result *first, double *x)
{
    int count = units(first, m);
    if (count < 1) return 0;
    for (int s = 0; s < n; s++) {
        if (units(&c[s], m) != count) return 0;
        for (int u = 0; u < count; u++) {
            double v = unit_value(&c[s], u, m);
            if (!isfinite(v) || !same_unit(&c[s], first, u, m)) return 0;
            x[(size_t)s * count + u] = v * tcb_rpt_metrics[m].scale;
        }
    }
    return 1;
}

/* The same split as `ref`: path, seed and (i, j) at every position. */
static int same_split(const tcb_cell_result *ref, const tcb_cell_result *c, tcb_error *err)
{
    int same = !strcmp(ref->split_path, c->split_path) && ref->split_seed == c->split_seed &&
               ref->n_pairs == c->n_pairs && !strcmp(ref->dataset, c->dataset) &&
               !strcmp(ref->sequence, c->sequence);
    for (int p = 0; same && p < ref->n_pairs; p++)
        same = ref->pairs[p].i == c->pairs[p].i && ref->pairs[p].j == c->pairs[p].j;
    /* Clips, when both scored them: the same clip split too. */
    if (same && ref->n_clips && c->n_clips) {
        same = !strcmp(ref->clips_path, c->clips_path) && ref->clips_seed == c->clips_seed &&
               ref->n_clips == c->n_clips;
        for (int k = 0; same && k < ref->n_clips; k++) same = ref->clips[k].start == c->clips[k].start;
        if (!same)
            return tcb_fail(err, TCB_ERR_INPUT,
                            "compare: %s/%s %s seed %d and %s/%s %s seed %d were not scored on the same clips "
                            "(%s seed %llu vs %s seed %llu): they cannot be paired",
                            ref->dataset, ref->sequence, ref->method, ref->seed, c->dataset, c->sequence,
                            c->method, c->seed, ref->clips_path, ref->clips_seed, c->clips_path, c->clips_seed);
    }
    if (same) return TCB_OK;
    return tcb_fail(err, TCB_ERR_INPUT,
                    "compare: %s/%s %s seed %d and %s/%s %s seed %d were not scored on the same pairs "
                    "(split %s seed %llu, %d pairs vs split %s seed %llu, %d pairs): they cannot be paired",
                    ref->dataset, ref->sequence, ref->method, ref->seed, c->dataset, c->sequence, c->method,
                    c->seed, ref->split_path, ref->split_seed, ref->n_pairs, c->split_path, c->split_seed,
                    c->n_pairs);
}

static int check_cells(const tcb_cell_result *a, int na, const tcb_cell_result *b, int nb, tcb_error *err)
{
    if (na < 1 || nb < 1)
        return tcb_fail(err, TCB_ERR_INPUT, "compare: needs at least one ok cell of each method (%d and %d)",
                        na, nb);
    if (a[0].n_pairs < 1 && a[0].n_clips < 1)
        return tcb_fail(err, TCB_ERR_INPUT, "compare: %s/%s %s seed %d has no pairs and no clips", a[0].dataset,
                        a[0].sequence, a[0].method, a[0].seed);
    for (int k = 0; k < na + nb; k++) {
        const tcb_cell_result *c = k < na ? &a[k] : &b[k - na];
        if (c->status != TCB_CELL_OK)
            return tcb_fail(err, TCB_ERR_INPUT, "compare: %s/%s %s seed %d is %s, not ok", c->dataset,
                            c->sequence, c->method, c->seed, tcb_cell_status_name(c->status));
        int rc = same_split(&a[0], c, err);
        if (rc) return rc;
    }
    return TCB_OK;
}

/* The test of the seed-averaged per-pair differences d[p]; p NaN when none
 * can be made. */
static int wilcoxon_p(const double *d, int n, double *p, tcb_error *err)
{
    tcb_wilcoxon_result w;
    int rc = tcb_wilcoxon(d, n, &w, err);
    *p = rc ? NAN : w.p;
    return rc;
}

/* Seed means of x[s][p] (s < seeds) into mean[p]. */
static void seed_means(const double *x, int seeds, int pairs, double *mean)
{
    for (int p = 0; p < pairs; p++) {
        double sum = 0.0;
        for (int s = 0; s < seeds; s++) sum += x[(size_t)s * pairs + p];
        mean[p] = sum / seeds;
    }
}

/* One metric from the filled matrices; scratch holds 2·pairs doubles. */
static int compare_metric(const double *xa, int na, const double *xb, int nb, int pairs, int m, int resamples,
                          double *scratch, tcb_cmp_metric *out, tcb_error *err)
{
    char label[32];
    snprintf(label, sizeof label, "compare/%s", tcb_rpt_metrics[m].key);
    tcb_boot_result boot;
    int rc = tcb_bootstrap_paired(xa, na, xb, nb, pairs, TCB_CMP_SEED, label, resamples, NULL, &boot, err);
    if (rc) return rc;
    double *ma = scratch, *mb = scratch + pairs;
    seed_means(xa, na, pairs, ma);
    seed_means(xb, nb, pairs, mb);
    out->mean_a = out->mean_b = 0.0;
    for (int p = 0; p < pairs; p++) {
        out->mean_a += ma[p] / pairs;
        out->mean_b += mb[p] / pairs;
        ma[p] -= mb[p];
    }
    out->has = 1, out->n = pairs;
    out->diff = boot.estimate, out->lo = boot.lo, out->hi = boot.hi;
    rc = wilcoxon_p(ma, pairs, &out->p, err);
    out->p_holm = out->p;
    return rc;
}

int tcb_compare_cells(const tcb_cell_result *a, int na, const tcb_cell_result *b, int nb, int resamples,
                      tcb_cmp *out, tcb_error *err)
{
    memset(out, 0, sizeof *out);
    int rc = check_cells(a, na, b, nb, err);
    if (rc) return rc;
    int most = a[0].n_pairs > a[0].n_clips ? a[0].n_pairs : a[0].n_clips;
    if (a[0].n_surface > most) most = a[0].n_surface;
    double *xa = malloc(sizeof *xa * (size_t)most * (size_t)(na + nb + 2));
    if (!xa) return tcb_fail(err, TCB_ERR_NOMEM, "compare: out of memory");
    *out = (tcb_cmp){.seeds_a = na, .seeds_b = nb, .n = a[0].n_pairs, .single_seed = na == 1 || nb == 1,
                     .resamples = resamples ? resamples : TCB_BOOT_RESAMPLES};
    for (int m = 0; m < TCB_N_METRICS && !rc; m++) {
        int count = units(&a[0], m);
        double *xb = xa + (size_t)count * na, *scratch = xb + (size_t)count * nb;
        if (!fill(a, na, m, &a[0], xa) || !fill(b, nb, m, &a[0], xb)) continue;
        rc = compare_metric(xa, na, xb, nb, count, m, resamples, scratch, &out->m[m], err);
        if (m == TCB_M_CORR) out->n_clips = count;
        if (is_recon(m)) out->n_frames = count;
    }
    free(xa);
    return rc;
}

int tcb_compare_means(const double *va, const double *vb, int n, int metric, int resamples, tcb_cmp *out,
                      tcb_error *err)
{
    out->seeds_a = out->seeds_b = 1;
    out->n = n;
    out->over_sequences = 1;
    out->resamples = resamples ? resamples : TCB_BOOT_RESAMPLES;
    double *scratch = malloc(sizeof *scratch * 2 * (size_t)(n > 0 ? n : 1));
    if (!scratch) return tcb_fail(err, TCB_ERR_NOMEM, "compare: out of memory");
    int rc = compare_metric(va, 1, vb, 1, n, metric, resamples, scratch, &out->m[metric], err);
    free(scratch);
    return rc;
}
