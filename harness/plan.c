/* `tcbench run CONFIG --dry-run`: the cells a run would compute and what
 * they would cost, without loading a sequence or fitting anything.
 *
 * Cells are numbered in grid order (dataset, sequence, method, seed) over
 * the whole config, so an id depends only on the config. A sequence is
 * sized from its first OBJ file (or generated, for synthetic data); each
 * method estimates its own cost from its measured step costs
 * (tcb_method_ops.estimate), and the harness adds its projection and
 * metrics, whose rank term compares every pair of target vertices. */
#include <stdio.h>
#include <string.h>

#include "harness/internal.h"
#include "tcb/registry.h"
#include "tcb/synth.h"

/* The rank metric per pair: 0.11 s at 10 002 vertices (nearest on crane:
 * 55 s for 500 pairs, one thread, Zen 4), quadratic in the vertex count. */
#define METRICS_S_PER_VERT2 (0.11 / (10002.0 * 10002.0))

typedef struct plan_totals {
    int cells, done, to_run, unknown;
    double seconds;  /* of the cells to run with known estimates */
} plan_totals;

static void duration_text(double s, char *out, size_t size)
{
    if (s < 0) snprintf(out, size, "?");
    else if (s < 90) snprintf(out, size, "%.0f s", s);
    else if (s < 5400) snprintf(out, size, "%.0f min", s / 60);
    else snprintf(out, size, "%.1f h", s / 3600);
}

/* Frames and vertices of sequence s of d; 0, 0 when the data are absent. */
static void probe(const tcb_dataset_spec *d, const char *name, int *n_frames, int *n_verts)
{
    tcb_error err = {0};
    *n_frames = *n_verts = 0;
    if (d->source == TCB_SOURCE_SYNTHETIC) {
        tcb_sequence seq = {0};
        if (!tcb_synth_generate(name, d->seed, d->frames, &seq, &err))
            *n_frames = seq.n_frames, *n_verts = seq.n_verts;
        tcb_sequence_free(&seq);
        return;
    }
    char dir[TCB_PATH_MAX];
    if (tcb_run_root_missing(d) || tcb_path_join(dir, sizeof dir, &err, "%s/%s", d->root, name)) return;
    if (tcb_sequence_probe_objdir(dir, n_frames, n_verts, &err)) *n_frames = *n_verts = 0;
}

static const char *cell_state(const char *run_dir, const tcb_dataset_spec *d, const char *seq,
                              const tcb_method_spec *m, int seed)
{
    char path[TCB_PATH_MAX];
    tcb_error err = {0};
    if (tcb_cell_path(path, sizeof path, run_dir, d->name, seq, m->label, seed, &err) || !tcb_is_file(path))
        return "missing";
    tcb_cell_result c;
    if (tcb_cell_load(path, &c, &err)) return "unreadable";
    const char *state = tcb_cell_status_name(c.status);
    tcb_cell_free(&c);
    return state;
}

static void estimate_cell(const tcb_method_spec *m, const tcb_cost_query *q, tcb_cost_estimate *e)
{
    const tcb_method_ops *ops = tcb_registry_find(m->method); /* checked before */
    void *self = NULL;
    tcb_error err = {0};
    e->fit_s = e->eval_s = -1;
    snprintf(e->basis, sizeof e->basis, "the method gives no estimate");
    if (ops->abi_version < 2 || !ops->estimate || ops->create(m->params_json, &self, &err)) return;
    ops->estimate(self, q, e);
    ops->destroy(self);
    if (e->eval_s >= 0 && q->n_verts > 0)
        e->eval_s += q->n_pairs * METRICS_S_PER_VERT2 * (double)q->n_verts * q->n_verts;
    else if (q->n_verts <= 0)
        e->eval_s = -1;
}

static void plan_method(FILE *out, const tcb_run_opts *opts, const char *run_dir, const tcb_dataset_spec *d, const char *seq,
                        const tcb_method_spec *m, const tcb_cost_query *q, int *id, int selected, plan_totals *t)
{
    tcb_cost_estimate e;
    estimate_cell(m, q, &e);
    for (int s = 0; s < m->n_seeds; s++, (*id)++) {
        if (!selected) continue;
        const char *state = cell_state(run_dir, d, seq, m, m->seeds[s]);
        int runs = opts->force || strcmp(state, "missing") == 0 || strcmp(state, "unreadable") == 0;
        char fit[32], eval[32];
        duration_text(e.fit_s, fit, sizeof fit);
        duration_text(e.eval_s, eval, sizeof eval);
        fprintf(out, "  %4d  %-24s %4d  %-10s %9s %9s  %s\n", *id, m->label, m->seeds[s], state, fit, eval,
                e.basis);
        t->cells++;
        if (!runs) {
            t->done++;
            continue;
        }
        t->to_run++;
        if (e.fit_s < 0 || e.eval_s < 0) t->unknown++;
        else t->seconds += e.fit_s + e.eval_s;
    }
}

static void plan_sequence(FILE *out, const tcb_config *cfg, const tcb_run_opts *opts, const char *run_dir,
                          const tcb_dataset_spec *d, const char *seq, int *id, plan_totals *t)
{
    tcb_cost_query q = {0, 0, cfg->eval_pairs, cfg->threads};
    probe(d, seq, &q.n_frames, &q.n_verts);
    if (q.n_frames) fprintf(out, "%s/%s: %d frames, %d vertices, %d pairs\n", d->name, seq, q.n_frames, q.n_verts,
                            q.n_pairs);
    else fprintf(out, "%s/%s: data absent, %d pairs\n", d->name, seq, q.n_pairs);
    fprintf(out, "  %4s  %-24s %4s  %-10s %9s %9s  %s\n", "id", "method", "seed", "state", "fit", "eval", "basis");
    for (int k = 0; k < cfg->n_methods; k++) {
        const tcb_method_spec *m = &cfg->methods[k];
        if (tcb_method_runs_on(m, d->name)) plan_method(out, opts, run_dir, d, seq, m, &q, id, tcb_run_selected(opts, m), t);
    }
}

int tcb_run_dry(const tcb_config *cfg, const tcb_run_opts *opts, FILE *out, tcb_error *err)
{
    const char *run_dir = opts->output ? opts->output : cfg->output;
    int rc = tcb_harness_load_plugins(cfg, err);
    if (!rc) rc = tcb_run_check_methods(cfg, opts, err);
    if (rc) return rc;
    fprintf(out, "%s: %s, %d thread%s per cell\n", cfg->path, run_dir, cfg->threads, cfg->threads == 1 ? "" : "s");
    plan_totals t = {0};
    int id = 0;
    for (int k = 0; k < cfg->n_datasets; k++) {
        const tcb_dataset_spec *d = &cfg->datasets[k];
        if (tcb_run_root_missing(d)) {
            char why[TCB_PATH_MAX + 64];
            tcb_run_missing_root_text(d, why, sizeof why);
            fprintf(out, "dataset %s: %s%s\n", d->name, why, d->optional ? " (optional: skipped by a run)" : "");
        }
        for (int s = 0; s < d->n_sequences; s++)
            plan_sequence(out, cfg, opts, run_dir, d, d->sequences[s].name, &id, &t);
    }
    char total[32];
    duration_text(t.seconds, total, sizeof total);
    fprintf(out, "cells: %d, %d finished, %d to run: about %s of wall time one after another", t.cells, t.done,
            t.to_run, total);
    if (t.unknown) fprintf(out, ", plus %d cell%s without an estimate", t.unknown, t.unknown == 1 ? "" : "s");
    fprintf(out, "\n");
    return TCB_OK;
}
