/* `tcbench run CONFIG --dry-run`: the cells a run would compute and what
 * they would cost, without loading a sequence or fitting anything.
 *
 * Cells are numbered in grid order (dataset, sequence, method, seed) over
 * the whole config, so an id depends only on the config. A sequence is
 * sized from its first OBJ file (or generated, for synthetic data); each
 * method estimates its own cost (tcb_method_ops.estimate), a trained one
 * by naming the preset whose costs `tcbench calibrate` measured, and the
 * harness prices it and adds its scoring of the pairs from the
 * calibrations (costs/calibration.h). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "costs/calibration.h"
#include "harness/harness_internal.h"
#include "tcb/dfaust.h"
#include "tcb/registry.h"
#include "tcb/synth.h"
#include "tcb/sysinfo.h"

typedef struct plan_totals {
    int cells, done, running, to_run;  /* running: held by a live process elsewhere */
    int unknown;                       /* cells to run with a part not estimated */
    double seconds;  /* the estimated parts of the cells to run */
    double *cell_s;  /* [to_run] each one's estimated seconds, in id order (--tasks) */
    int cap;
} plan_totals;

static void duration_text(double s, char *out, size_t size)
{
    if (s < 0) snprintf(out, size, "?");
    else if (s < 10) snprintf(out, size, "%.1f s", s);
    else if (s < 90) snprintf(out, size, "%.0f s", s);
    else if (s < 5400) snprintf(out, size, "%.0f min", s / 60);
    else snprintf(out, size, "%.1f h", s / 3600);
}

/* Frames and vertices of sequence `name` of d; 0, 0 when the data are absent. */
static void probe_source(const tcb_dataset_spec *d, const char *name, int *n_frames, int *n_verts)
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
    if (tcb_run_root_missing(d)) return;
    int rc = d->source == TCB_SOURCE_DFAUST
                 ? tcb_dfaust_probe(d->root, name, d->subjects, d->n_subjects, n_frames, n_verts, &err)
             : d->source == TCB_SOURCE_PCL_SEQ
                 ? (tcb_path_join(dir, sizeof dir, &err, "%s/%s", d->root, name)
                        ? TCB_ERR_INPUT
                        : tcb_sequence_probe_pcl_seq(dir, d->points, n_frames, n_verts, &err))
             : tcb_path_join(dir, sizeof dir, &err, "%s/%s%s", d->root, name, d->source == TCB_SOURCE_CLIPDIR ? "/gt" : "")
                 ? TCB_ERR_INPUT
                 : tcb_sequence_probe_objdir(dir, n_frames, n_verts, &err);
    if (rc) *n_frames = *n_verts = 0;
}

/* The same for a grid sequence: a clip (s->clip_of) has its clip's frames
 * when its sequence reaches that far. */
static void probe(const tcb_dataset_spec *d, const tcb_sequence_spec *s, int *n_frames, int *n_verts)
{
    probe_source(d, s->clip_of[0] ? s->clip_of : s->name, n_frames, n_verts);
    if (s->clip_of[0] && *n_frames >= s->start + TCB_CLIP_FRAMES) *n_frames = TCB_CLIP_FRAMES;
    else if (s->clip_of[0]) *n_frames = *n_verts = 0;
}

/* done, failed, diverged, unreadable, missing, "running (host pid, age;
 * progress)" while a lock whose holder counts is on a cell without a result,
 * or "stale (host pid: why, ...)" when the next run will take that lock over
 * (the holder was killed, or its machine went away). */
static void cell_state_message(const char *run_dir, const tcb_run_opts *opts, const tcb_dataset_spec *d,
                               const char *seq, const tcb_method_spec *m, int seed, char *out, size_t size,
                               char *msg, size_t msg_size)
{
    if (msg) msg[0] = '\0';
    char path[TCB_PATH_MAX];
    tcb_error err = {0};
    snprintf(out, size, "missing");
    if (tcb_cell_path(path, sizeof path, run_dir, d->name, seq, m->label, seed, &err)) return;
    tcb_lock_info h;
    if (!tcb_is_file(path)) {
        if (tcb_cell_lock_holder(path, &h)) return;
        const char *stale = tcb_cell_lock_stale_reason(&h, tcb_run_lock_timeout(opts));
        snprintf(out, size, "%s (%s pid %ld%s%s, heartbeat %.0f s ago%s%s)", stale ? "stale" : "running", h.host, h.pid,
                 stale ? ": " : "", stale ? stale : "", h.heartbeat_age_s, h.progress[0] ? "; " : "", h.progress);
        return;
    }
    tcb_cell_result c;
    if (tcb_cell_load(path, &c, &err)) {
        snprintf(out, size, "unreadable");
        return;
    }
    snprintf(out, size, "%s", c.status == TCB_CELL_OK ? "done" : tcb_cell_status_name(c.status));
    if (msg) snprintf(msg, msg_size, "%s", c.message);
    tcb_cell_free(&c);
}

static void cell_state(const char *run_dir, const tcb_run_opts *opts, const tcb_dataset_spec *d, const char *seq,
                       const tcb_method_spec *m, int seed, char *out, size_t size)
{
    cell_state_message(run_dir, opts, d, seq, m, seed, out, size, NULL, 0);
}

/* A run computes the cell (a stale lock it takes over). */
static int state_runs(const char *state)
{
    return !strcmp(state, "missing") || !strcmp(state, "unreadable") || !strcmp(state, "failed") ||
           !strncmp(state, "stale", 5);
}

static void estimate_cell(const tcb_calibration_set *cals, const tcb_grid_cell *c, const tcb_cost_query *q,
                          int surface_samples, tcb_cost_estimate *e)
{
    const tcb_method_spec *m = c->method;
    char sequence[TCB_COST_SEQUENCE_MAX]; /* a unit measured on the cell's sequence prices its cells (costs/calibration.h) */
    snprintf(sequence, sizeof sequence, "%s/%s", c->dataset->name, c->sequence->name);
    const tcb_method_ops *ops = tcb_registry_find(m->method); /* checked before */
    void *self = NULL;
    tcb_error err = {0};
    memset(e, 0, sizeof *e);
    e->fit_s = e->eval_s = -1;
    snprintf(e->basis, sizeof e->basis, "the method gives no estimate");
    if (ops->abi_version < 2 || !ops->estimate || ops->create(m->params_json, &self, &err)) return;
    ops->estimate(self, q, e);
    ops->destroy(self);
    tcb_cost_price_cell(cals, ops->name, sequence, q, tcb_method_has_surface(ops) ? surface_samples : 0, e);
}

/* The wall time of the cells' seconds run as `tasks` concurrent one-cell
 * tasks taking the cells in id order, each as a task ends (a Slurm array
 * with %tasks). */
static double tasks_wall_time(const double *cell_s, int n, int tasks)
{
    double *end = calloc((size_t)tasks, sizeof *end), wall = 0;
    if (!end) return -1;
    for (int k = 0; k < n; k++) {
        int first = 0; /* the task slot that frees first */
        for (int t = 1; t < tasks; t++)
            if (end[t] < end[first]) first = t;
        end[first] += cell_s[k];
        if (end[first] > wall) wall = end[first];
    }
    free(end);
    return wall;
}

typedef struct plan_walk {
    FILE *out;
    const tcb_calibration_set *cals;
    const tcb_config *cfg;
    const tcb_run_opts *opts;
    const char *run_dir;
    const tcb_sequence_spec *current; /* the sequence whose header was printed */
    char revision[64];                /* tcbench's (tcb_git_revision): a measured cell's must match */
    tcb_cost_query q;
    plan_totals t;
} plan_walk;

static void sequence_header(plan_walk *w, const tcb_dataset_spec *d, const tcb_sequence_spec *s)
{
    const char *seq = s->name;
    if (tcb_run_root_missing(d) && s == &d->sequences[0]) {
        char why[TCB_PATH_MAX + 64];
        tcb_run_missing_root_text(d, why, sizeof why);
        fprintf(w->out, "dataset %s: %s%s\n", d->name, why, d->optional ? " (optional: skipped by a run)" : "");
    }
    /* The clip protocol's transfers count as pairs (16 a clip; at most
     * the configured clips, fewer on a short sequence; one fitted per
     * clip is one clip). */
    const tcb_config *c = w->cfg;
    int clips = c->fit_per_clip ? 1 : c->eval_clips;
    int pairs = (c->protocols & TCB_PROTOCOL_PAIRS ? c->eval_pairs : 0) +
                (c->protocols & TCB_PROTOCOL_CLIPS ? clips * (TCB_CLIP_FRAMES - 1) : 0);
    w->q = (tcb_cost_query){0, 0, pairs, c->threads};
    probe(d, s, &w->q.n_frames, &w->q.n_verts);
    if (w->q.n_frames)
        fprintf(w->out, "%s/%s: %d frames, %d vertices, %d pairs\n", d->name, seq, w->q.n_frames, w->q.n_verts,
                w->q.n_pairs);
    else
        fprintf(w->out, "%s/%s: data absent, %d pairs\n", d->name, seq, w->q.n_pairs);
    fprintf(w->out, "  %4s  %-24s %4s  %-10s %9s %9s  %s\n", "id", "method", "seed", "state", "fit", "eval", "basis");
}

static int add_cell_seconds(plan_totals *t, double seconds)
{
    if (t->to_run > t->cap) {
        int cap = t->cap ? 2 * t->cap : 64;
        double *grown = realloc(t->cell_s, (size_t)cap * sizeof *grown);
        if (!grown) return TCB_ERR_NOMEM;
        t->cell_s = grown, t->cap = cap;
    }
    t->cell_s[t->to_run - 1] = seconds;
    return TCB_OK;
}

/* A finished cell of the same method on the same sequence, another seed's,
 * measured by this revision of tcbench, prices this one from what it
 * measured: its fit, and its evaluation per pair times this cell's pairs.
 * A measurement knows what the counts the calibration scales by do not (how
 * far apart the frames of a pair lie, how a shape's thin parts lengthen a
 * search: docs/cluster.md); one by other code says little about this
 * code's speed. 0 when no such cell is there. */
static int price_from_sibling(const plan_walk *w, const tcb_grid_cell *c, tcb_cost_estimate *e)
{
    const tcb_method_spec *m = c->method;
    for (int k = 0; k < m->n_seeds; k++) {
        char path[TCB_PATH_MAX];
        tcb_error err = {0};
        tcb_cell_result r;
        if (m->seeds[k] == c->seed ||
            tcb_cell_path(path, sizeof path, w->run_dir, c->dataset->name, c->sequence->name, m->label, m->seeds[k],
                          &err) ||
            !tcb_is_file(path) || tcb_cell_load(path, &r, &err))
            continue;
        /* the clip protocol's transfers count as pairs, as in the query */
        int pairs = r.n_pairs + r.n_clips * (TCB_CLIP_FRAMES - 1);
        int ok = r.status == TCB_CELL_OK && pairs > 0 && r.fit_s >= 0 && r.eval_s >= 0 &&
                 !strcmp(r.git_revision, w->revision);
        if (ok) {
            char fit[32], eval[32];
            duration_text(r.fit_s, fit, sizeof fit);
            duration_text(r.eval_s, eval, sizeof eval);
            e->fit_s = r.fit_s;
            e->eval_s = r.eval_s * w->q.n_pairs / pairs;
            snprintf(e->basis, sizeof e->basis, "measured: seed %d's cell (fit %s, evaluation %s for %d pairs)",
                     m->seeds[k], fit, eval, pairs);
        }
        tcb_cell_free(&r);
        if (ok) return 1;
    }
    return 0;
}

static int plan_cell(void *ctx, const tcb_grid_cell *c)
{
    plan_walk *w = ctx;
    if (!tcb_run_selected(w->opts, c->method) || (w->opts->cells && !w->opts->cells[c->id])) return TCB_OK;
    if (w->current != c->sequence) sequence_header(w, c->dataset, c->sequence);
    w->current = c->sequence;
    char state[TCB_PATH_MAX];
    cell_state(w->run_dir, w->opts, c->dataset, c->sequence->name, c->method, c->seed, state, sizeof state);
    int runs = w->opts->force || state_runs(state);
    tcb_cost_estimate e;
    estimate_cell(w->cals, c, &w->q, w->cfg->surface_samples, &e);
    if (runs) price_from_sibling(w, c, &e);
    char fit[32], eval[32];
    duration_text(e.fit_s, fit, sizeof fit);
    duration_text(e.eval_s, eval, sizeof eval);
    /* The state's first word: the holder of a running cell is `status`'s to show. */
    fprintf(w->out, "  %4d  %-24s %4d  %-10.*s %9s %9s  %s\n", c->id, c->method->label, c->seed,
            (int)strcspn(state, " "), state, fit, eval, e.basis);
    w->t.cells++;
    if (!runs) {
        if (!strncmp(state, "running", 7)) w->t.running++;
        else w->t.done++;
        return TCB_OK;
    }
    w->t.to_run++;
    w->t.unknown += e.fit_s < 0 || e.eval_s < 0;
    double seconds = (e.fit_s > 0 ? e.fit_s : 0) + (e.eval_s > 0 ? e.eval_s : 0);
    w->t.seconds += seconds;
    return add_cell_seconds(&w->t, seconds);
}

/* The calibrations in the order they are read. */
static void print_sources(FILE *out, const tcb_calibration_set *s)
{
    fprintf(out, "costs from (first match wins):");
    for (int k = 0; k < s->n; k++)
        fprintf(out, "%s %s (%s)", k ? ";" : "", s->c[k].origin, s->c[k].machine);
    fprintf(out, "\n");
}

static void print_totals(FILE *out, const plan_totals *t, int tasks)
{
    char total[32];
    duration_text(t->seconds, total, sizeof total);
    fprintf(out, "cells: %d, %d finished, ", t->cells, t->done);
    if (t->running) fprintf(out, "%d running in other processes, ", t->running);
    fprintf(out, "%d to run: about %s of wall time one after another", t->to_run, total);
    if (t->unknown)
        fprintf(out, ", plus what is unknown of %d cell%s (\"?\" above)", t->unknown, t->unknown == 1 ? "" : "s");
    fprintf(out, "\n");
    if (tasks < 1) return;
    duration_text(tasks_wall_time(t->cell_s, t->to_run, tasks), total, sizeof total);
    fprintf(out, "as %d concurrent one-cell tasks (a Slurm array with %%%d), in id order: about %s of wall time%s\n",
            tasks, tasks, total, t->unknown ? ", the unknown parts left out" : "");
}

int tcb_run_dry(const tcb_config *cfg, const tcb_run_opts *opts, FILE *out, tcb_error *err)
{
    const char *run_dir = opts->output ? opts->output : cfg->output;
    int rc = tcb_harness_load_plugins(cfg, err);
    if (!rc) rc = tcb_run_check_methods(cfg, opts, err);
    if (rc) return rc;
    tcb_calibration_set cals;
    if (!rc) rc = tcb_calibration_set_load(run_dir, &cals, err);
    if (rc) return rc;
    fprintf(out, "%s: %s, %d thread%s per cell\n", cfg->path, run_dir, cfg->threads, cfg->threads == 1 ? "" : "s");
    print_sources(out, &cals);
    plan_walk w = {out, &cals, cfg, opts, run_dir, NULL, "", {0}, {0}};
    tcb_git_revision(w.revision, sizeof w.revision);
    rc = tcb_grid_for_each(cfg, plan_cell, &w);
    if (rc) rc = tcb_fail(err, TCB_ERR_NOMEM, "out of memory");
    else print_totals(out, &w.t, opts->tasks);
    free(w.t.cell_s);
    tcb_calibration_set_free(&cals);
    return rc;
}

typedef struct list_walk {
    FILE *out;
    const char *run_dir;
    const tcb_run_opts *opts;
    const tcb_config *cfg;
    const unsigned char *refused; /* [n_methods] 1: a run leaves the method's cells alone */
} list_walk;

static int list_cell(void *ctx, const tcb_grid_cell *c)
{
    const list_walk *w = ctx;
    char state[TCB_PATH_MAX];
    cell_state(w->run_dir, w->opts, c->dataset, c->sequence->name, c->method, c->seed, state, sizeof state);
    /* Its cell there is another method's under this label: a run refuses
     * to touch it, so it is not this config's "done". */
    const char *other = w->refused[c->method - w->cfg->methods] ? " (other settings)" : "";
    fprintf(w->out, "%5d  %-12s %-20s %-24s %4d  %s%s\n", c->id, c->dataset->name, c->sequence->name,
            c->method->label, c->seed, state, other);
    return TCB_OK;
}

int tcb_run_list_cells(const tcb_config *cfg, const tcb_run_opts *opts, FILE *out, tcb_error *err)
{
    list_walk w = {out, opts->output ? opts->output : cfg->output, opts, cfg, NULL};
    /* The plug-ins, for their digests: a rebuilt one's cells are not done. */
    unsigned char *refused = calloc((size_t)cfg->n_methods + 1, 1);
    int rc = refused ? tcb_harness_load_plugins(cfg, err) : tcb_fail(err, TCB_ERR_NOMEM, "out of memory");
    if (!rc) rc = tcb_run_dir_refusals(cfg, w.run_dir, opts, refused, err);
    w.refused = refused;
    if (!rc) fprintf(out, "%5s  %-12s %-20s %-24s %4s  %s\n", "id", "dataset", "sequence", "method", "seed", "state");
    if (!rc) rc = tcb_grid_for_each(cfg, list_cell, &w);
    free(refused);
    return rc;
}

/* ---- tcbench status ---------------------------------------------------- */

/* Ids in Slurm's --array syntax ("0-3,7"), built in increasing order. */
typedef struct id_ranges {
    int lo, hi; /* the current run of ids, -1: none */
    char text[4096];
} id_ranges;

typedef struct status_walk {
    FILE *out;
    const char *run_dir;
    const tcb_run_opts *opts;
    const tcb_slurm_queue *queue;
    int n_done, n_diverged, n_failed, n_running, n_stale, n_missing, n_queued;
    id_ranges resubmit; /* the ids a run would compute (missing, failed or stale, not queued) */
    id_ranges queued;
    char failures[8192];
} status_walk;

static void flush_range(id_ranges *r)
{
    if (r->lo < 0) return;
    const char *sep = r->text[0] ? "," : "";
    size_t used = strlen(r->text);
    if (r->lo == r->hi) snprintf(r->text + used, sizeof r->text - used, "%s%d", sep, r->lo);
    else snprintf(r->text + used, sizeof r->text - used, "%s%d-%d", sep, r->lo, r->hi);
    r->lo = r->hi = -1;
}

static void add_id(id_ranges *r, int id)
{
    if (r->hi >= 0 && id == r->hi + 1) r->hi = id;
    else flush_range(r), r->lo = r->hi = id;
}

/* A diverged cell is a result (listed, with why); a failed one has none
 * and is computed again by the next run, as a missing one is, or one whose
 * lock is stale, unless a Slurm task that will run it is queued. */
static int status_cell(void *ctx, const tcb_grid_cell *c)
{
    status_walk *w = ctx;
    char state[TCB_PATH_MAX], msg[TCB_ERRMSG_MAX];
    cell_state_message(w->run_dir, w->opts, c->dataset, c->sequence->name, c->method, c->seed, state, sizeof state,
                       msg, sizeof msg);
    int missing = !strcmp(state, "missing") || !strcmp(state, "unreadable"), failed = !strcmp(state, "failed");
    int running = !strncmp(state, "running", 7), stale = !strncmp(state, "stale", 5);
    int queued = state_runs(state) && w->queue->queued && w->queue->queued[c->id];
    if (!strcmp(state, "done")) w->n_done++;
    else if (running || stale) {
        w->n_running += running;
        w->n_stale += stale && !queued;
        fprintf(w->out, "%-8s %5d  %s/%s/%s seed %d: %s%s\n", running ? "running" : "stale", c->id, c->dataset->name,
                c->sequence->name, c->method->label, c->seed, strchr(state, '('),
                queued ? " (queued again in Slurm)" : "");
    } else if (!missing) {
        w->n_failed += failed && !queued;
        w->n_diverged += !failed;
        size_t used = strlen(w->failures);
        snprintf(w->failures + used, sizeof w->failures - used, "%-8s %5d  %s/%s/%s seed %d: %s%s\n", state, c->id,
                 c->dataset->name, c->sequence->name, c->method->label, c->seed, msg,
                 queued ? " (queued again in Slurm)" : "");
    }
    w->n_missing += missing && !queued;
    w->n_queued += queued;
    if (queued) add_id(&w->queued, c->id);
    else if (state_runs(state)) add_id(&w->resubmit, c->id);
    return TCB_OK;
}

int tcb_run_status(const tcb_config *cfg, const tcb_run_opts *opts, FILE *out, tcb_error *err)
{
    const char *run_dir = opts->output ? opts->output : cfg->output;
    tcb_slurm_queue queue;
    char note[640];
    if (tcb_slurm_queue_read(run_dir, tcb_grid_count(cfg), &queue, note, sizeof note))
        return tcb_fail(err, TCB_ERR_NOMEM, "out of memory");
    if (note[0]) tcb_report_log(&opts->reporter, TCB_LOG_WARN, "%s", note);
    status_walk w = {.out = out, .run_dir = run_dir, .opts = opts, .queue = &queue, .resubmit = {-1, -1, ""}, .queued = {-1, -1, ""}};
    tcb_grid_for_each(cfg, status_cell, &w);
    flush_range(&w.resubmit);
    flush_range(&w.queued);
    fputs(w.failures, out);
    if (w.n_queued)
        fprintf(out, "queued   %s: pending or running in Slurm (%s %s)\n", w.queued.text,
                strchr(queue.jobs, ' ') ? "jobs" : "job", queue.jobs);
    fprintf(out, "%s: %d cells: %d done, %d diverged, %d failed, %d running, %d stale, %d missing", w.run_dir,
            tcb_grid_count(cfg), w.n_done, w.n_diverged, w.n_failed, w.n_running, w.n_stale, w.n_missing);
    if (queue.asked) fprintf(out, ", %d queued in Slurm", w.n_queued);
    fprintf(out, "\n");
    if (w.n_missing || w.n_failed || w.n_stale)
        fprintf(out, "resubmit the cells a run computes (%d missing, %d failed, %d stale): --array=%s\n", w.n_missing,
                w.n_failed, w.n_stale, w.resubmit.text);
    tcb_slurm_queue_free(&queue);
    return TCB_OK;
}
