/* A fake run directory for the report and check tests: cell files written
 * with tcb_cell_save from explicit per-vertex errors, so the tests can
 * recompute every expected table value by hand (two-pass mean and std)
 * instead of trusting the pooling code they test. Header-only: each test
 * program is one translation unit. */
#ifndef TCB_FAKE_RUN_H
#define TCB_FAKE_RUN_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cjson/cJSON.h>

#include "tcb/fsutil.h"
#include "tcb/metrics.h"
#include "tcb/results.h"

#define FAKE_PAIRS 2
#define FAKE_NV 5

typedef struct fake_cell {
    const char *dataset, *sequence, *role, *method;
    int seed;
    tcb_cell_status status;
    double base;  /* scales the method's errors: lower is better */
    int has_cd;   /* the method reconstructs */
    int no_geo;   /* written as before the geodesic error existed: none */
} fake_cell;

/* Per-vertex Euclidean error of vertex k in pair p. */
static inline double fake_sl2(const fake_cell *c, int p, int k)
{
    /* Irregular factors keep table values off the .xx5 rounding boundaries. */
    return c->base * (1.0 + 0.231 * k + 0.417 * p + 0.137 * c->seed);
}

/* Normalized rank: the same for every method, so the rank column ties. */
static inline double fake_rank(int k) { return 0.01 * (k + 1); }

static inline double fake_cd(const fake_cell *c, int p) { return c->base * 0.01 * (1 + p); }

/* Normalised geodesic error of vertex k in pair p: above the Euclidean one,
 * spread over the geodesic PCK's range. */
static inline double fake_geo(const fake_cell *c, int p, int k)
{
    return c->base * (2.0 + 0.1937 * k + 0.3113 * p + 0.1013 * c->seed);
}

/* Vertices scored by the straight-line fallback: one in the second pair of
 * a method without reconstruction, none elsewhere. */
static inline int fake_unreachable(const fake_cell *c, int p) { return c->has_cd ? 0 : p; }

static inline void fake_pair_geo(const fake_cell *c, int p, tcb_pair_metrics *m)
{
    for (int k = 0; k < FAKE_NV; k++) tcb_stat_push(&m->geo, fake_geo(c, p, k));
    for (int s = 0; s < TCB_GEO_PCK_STEPS; s++) {
        int hits = 0;
        for (int k = 0; k < FAKE_NV; k++) hits += fake_geo(c, p, k) <= tcb_geo_pck_threshold(s);
        m->geo_pck[s] = (double)hits / FAKE_NV;
        m->geo_auc += m->geo_pck[s] / TCB_GEO_PCK_STEPS;
    }
    m->geo_unreachable = fake_unreachable(c, p);
}

static inline void fake_pair(const fake_cell *c, int p, tcb_pair_metrics *m)
{
    memset(m, 0, sizeof *m);
    for (int k = 0; k < FAKE_NV; k++) {
        double e = fake_sl2(c, p, k);
        tcb_stat_push(&m->sl2, e);
        tcb_stat_push(&m->sl2sq, e * e);
        tcb_stat_push(&m->rank, fake_rank(k));
    }
    for (int s = 0; s < TCB_PCK_STEPS; s++) {
        int hits = 0;
        for (int k = 0; k < FAKE_NV; k++) hits += pow(fake_sl2(c, p, k), 2) <= tcb_pck_threshold(s);
        m->pck[s] = (double)hits / FAKE_NV;
        m->auc += m->pck[s] / TCB_PCK_STEPS;
    }
    if (!c->no_geo) fake_pair_geo(c, p, m);
}

/* Pair p's frames: (0, 1) and (3, 1), frame distances 1 and 2 (both orders). */
static inline int fake_i(int p) { return p ? 3 : 0; }
static inline int fake_j(int p) { (void)p; return 1; }
static inline int fake_gap(int p) { return p + 1; }

/* Writes the cell to its place under `run`; returns 0 on success. */
static inline int fake_write(const char *run, const fake_cell *c)
{
    tcb_cell_result r;
    memset(&r, 0, sizeof r);
    snprintf(r.dataset, sizeof r.dataset, "%s", c->dataset);
    snprintf(r.sequence, sizeof r.sequence, "%s", c->sequence);
    snprintf(r.role, sizeof r.role, "%s", c->role);
    snprintf(r.method, sizeof r.method, "%s", c->method);
    snprintf(r.method_impl, sizeof r.method_impl, "%s-impl", c->method);
    r.params_json = "{\"k\":1}";
    r.seed = c->seed;
    r.status = c->status;
    snprintf(r.git_revision, sizeof r.git_revision, "test");
    snprintf(r.split_path, sizeof r.split_path, "splits/%s.json", c->sequence);
    r.split_seed = 2021;
    tcb_pair_record pairs[FAKE_PAIRS];
    tcb_summary_init(&r.summary);
    if (c->status == TCB_CELL_OK) {
        r.n_pairs = FAKE_PAIRS;
        r.pairs = pairs;
        for (int p = 0; p < FAKE_PAIRS; p++) {
            tcb_pair_metrics m;
            fake_pair(c, p, &m);
            double cd = c->has_cd ? fake_cd(c, p) : NAN;
            pairs[p] = (tcb_pair_record){fake_i(p), fake_j(p), m.sl2,    m.sl2sq,   m.rank,
                                         m.auc,     cd,        m.geo,    m.geo_auc, m.geo_unreachable};
            tcb_summary_add_pair(&r.summary, &m, cd);
        }
    } else {
        snprintf(r.message, sizeof r.message, "loss became NaN at iteration 7");
    }
    char path[4096];
    tcb_error err = {0};
    if (tcb_cell_path(path, sizeof path, run, c->dataset, c->sequence, c->method, c->seed, &err) ||
        tcb_cell_save(path, &r, &err)) {
        fprintf(stderr, "fake_write: %s\n", err.msg);
        return 1;
    }
    return 0;
}

/* Rewrites the cell of (run, dataset, sequence, method, seed 0) through
 * edit(root, arg) on its JSON, for what fake_write cannot say (another
 * method_impl, pairs at other distances); returns 0 on success. */
static inline int fake_edit(const char *run, const fake_cell *c, void (*edit)(cJSON *root, const void *arg),
                            const void *arg)
{
    char path[4096], *text;
    tcb_error err = {0};
    if (tcb_cell_path(path, sizeof path, run, c->dataset, c->sequence, c->method, c->seed, &err) ||
        tcb_read_file(path, &text, NULL, &err)) {
        fprintf(stderr, "fake_edit: %s\n", err.msg);
        return 1;
    }
    cJSON *root = cJSON_Parse(text);
    free(text);
    if (!root) return 1;
    edit(root, arg);
    char *out = cJSON_Print(root);
    cJSON_Delete(root);
    int rc = !out || tcb_write_file_atomic(path, out, strlen(out), &err);
    free(out);
    return rc;
}

/* Two-pass population mean and std of `n` values. */
static inline void fake_mean_std(const double *v, int n, double *mean, double *std)
{
    double s = 0, q = 0;
    for (int k = 0; k < n; k++) s += v[k];
    *mean = s / n;
    for (int k = 0; k < n; k++) q += (v[k] - *mean) * (v[k] - *mean);
    *std = sqrt(q / n);
}

#endif
