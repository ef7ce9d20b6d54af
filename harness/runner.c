/* The grid runner: datasets × sequences × methods × seeds.
 *
 * Each sequence is loaded once and its split obtained once; then every
 * (method, seed) cell either is skipped (its file exists and was made with
 * the same settings) or is computed by tcb_cell_run and saved atomically.
 * Everything a cell computes is a function of the config and the seed, so a
 * killed run, rerun, produces the same cell files as an uninterrupted one. */
#include "tcb/runner.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "harness/harness_internal.h"
#include "tcb/dfaust.h"
#include "tcb/fsutil.h"
#include "tcb/registry.h"
#include "tcb/synth.h"
#include "tcb/sysinfo.h"

/* What the grid loop carries from one sequence to the next. */
typedef struct run_state {
    const tcb_config *cfg;
    const tcb_run_opts *opts;
    const char *run_dir;
    char git_revision[64];
    tcb_run_stats *stats;
    const unsigned char *refused; /* [n_methods] 1: the run directory refused the method (run_config.c) */
} run_state;

/* A cell's work directory holds only its method's checkpoints (the model
 * after fit, a training in progress, an external command's own files, in
 * subdirectories too). --force starts the cell from nothing, so it empties
 * the directory, and fails when it cannot (a model left there could be
 * resumed); otherwise only killed writers' temporaries go. */
static int prepare_work_dir(const char *work, int force, tcb_error *err)
{
    if (force) return tcb_empty_dir(work, err);
    tcb_remove_stale_temps(work, "");
    return TCB_OK;
}

int tcb_harness_load_plugins(const tcb_config *cfg, tcb_error *err)
{
    for (int k = 0; k < cfg->n_plugins; k++) {
        int rc = tcb_registry_load_plugin(cfg->plugins[k], err);
        if (rc) {
            tcb_error_prefix(err, "%s: plugins[%d]: ", cfg->path, k);
            return rc;
        }
    }
    return TCB_OK;
}

static const tcb_method_spec *find_label(const tcb_config *cfg, const char *label)
{
    for (int k = 0; k < cfg->n_methods; k++)
        if (strcmp(cfg->methods[k].label, label) == 0) return &cfg->methods[k];
    return NULL;
}

double tcb_run_lock_timeout(const tcb_run_opts *opts)
{
    return opts->lock_timeout_s > 0 ? opts->lock_timeout_s : TCB_LOCK_TIMEOUT_DEFAULT_S;
}

/* Every selected method must exist and accept its params before any work
 * starts: a typo should cost seconds, not the hours of the cells before it. */
int tcb_run_check_methods(const tcb_config *cfg, const tcb_run_opts *opts, tcb_error *err)
{
    if (opts->only_method && !find_label(cfg, opts->only_method))
        return tcb_fail(err, TCB_ERR_INPUT, "--only: %s has no method labelled '%s'", cfg->path,
                        opts->only_method);
    for (int k = 0; k < cfg->n_methods; k++) {
        const tcb_method_spec *m = &cfg->methods[k];
        if (!tcb_run_selected(opts, m)) continue;
        const tcb_method_ops *ops = tcb_registry_find(m->method);
        if (!ops) {
            char list[1024] = "";
            for (int r = 0; r < tcb_registry_count(); r++) {
                size_t used = strlen(list);
                snprintf(list + used, sizeof list - used, "%s%s", r ? ", " : "",
                         tcb_registry_get(r)->name);
            }
            return tcb_fail(err, TCB_ERR_INPUT,
                            "%s: methods[%d]: no method named '%s' (registered: %s)", cfg->path, k,
                            m->method, list);
        }
        void *self = NULL;
        int rc = ops->create(m->params_json, &self, err);
        if (rc) {
            tcb_error_prefix(err, "%s: methods[%d].params: ", cfg->path, k);
            return rc;
        }
        ops->destroy(self);
    }
    return TCB_OK;
}

/* Sequence `name` of d as its source gives it, prepared with *lo. */
static int load_source(const tcb_dataset_spec *d, const char *name, const tcb_load_opts *lo, tcb_sequence *seq,
                       tcb_error *err)
{
    if (d->source == TCB_SOURCE_SYNTHETIC) {
        int rc = tcb_synth_generate(name, d->seed, d->frames, seq, err);
        return rc ? rc : tcb_sequence_prepare(seq, lo, err);
    }
    if (d->source == TCB_SOURCE_DFAUST)
        return tcb_sequence_load_dfaust(d->root, name, d->subjects, d->n_subjects, lo, seq, err);
    char dir[TCB_PATH_MAX];
    int rc = tcb_path_join(dir, sizeof dir, err, "%s/%s", d->root, name);
    if (!rc && !tcb_is_dir(dir)) rc = tcb_fail(err, TCB_ERR_IO, "%s: no such directory", dir);
    if (rc) return rc;
    /* the clip folders (17 frames) and point sequences: no cache */
    if (d->source == TCB_SOURCE_CLIPDIR) rc = tcb_sequence_read_clipdir(dir, name, seq, err);
    else if (d->source == TCB_SOURCE_PCL_SEQ) rc = tcb_sequence_read_pcl_seq(dir, name, d->points, seq, err);
    else return tcb_sequence_load_objdir(dir, name, lo, seq, err);
    return rc ? rc : tcb_sequence_prepare(seq, lo, err);
}

/* A clip of sequence s->clip_of fitted on its own: that sequence read
 * raw (no normalization, no alignment: both are the clip's own), the
 * clip's frames cut out and prepared as a sequence named s->name. */
static int load_clip(const tcb_dataset_spec *d, const tcb_sequence_spec *s, const tcb_load_opts *lo,
                     tcb_sequence *seq, tcb_error *err)
{
    tcb_load_opts raw = *lo;
    raw.norm = TCB_NORM_NONE, raw.align_samples = 0;
    tcb_sequence whole = {0};
    int rc = load_source(d, s->clip_of, &raw, &whole, err);
    if (!rc) rc = tcb_sequence_cut(&whole, s->start, TCB_CLIP_FRAMES, s->name, seq, err);
    tcb_sequence_free(&whole);
    return rc ? rc : tcb_sequence_prepare(seq, lo, err);
}

int tcb_harness_load_sequence(const tcb_config *cfg, const tcb_dataset_spec *d, const tcb_sequence_spec *s,
                              const tcb_reporter *reporter, tcb_sequence *seq, tcb_error *err)
{
    tcb_load_opts lo = {d->norm, cfg->pool_size, cfg->pool_seed, cfg->cache_dir[0] ? cfg->cache_dir : NULL,
                        d->align_samples, reporter};
    int rc = s->clip_of[0] ? load_clip(d, s, &lo, seq, err) : load_source(d, s->name, &lo, seq, err);
    if (!rc && cfg->fit_per_clip && seq->n_frames != TCB_CLIP_FRAMES)
        rc = tcb_fail(err, TCB_ERR_INPUT,
                      "fitted per clip, a sequence is one clip of %d frames, this one has %d (name its clips "
                      "with \"clip_starts\")",
                      TCB_CLIP_FRAMES, seq->n_frames);
    if (rc) {
        tcb_sequence_free(seq);
        tcb_error_prefix(err, "dataset %s, sequence %s: ", d->name, s->name);
        return rc;
    }
    seq->input_points = cfg->input_points;
    seq->draw_with_replacement = d->with_replacement;
    seq->input_normals = cfg->input_normals;
    return TCB_OK;
}

int tcb_run_load_sequence(const tcb_config *cfg, const char *dataset, const char *sequence, tcb_sequence *out,
                          tcb_error *err)
{
    const tcb_dataset_spec *d;
    const tcb_sequence_spec *s;
    memset(out, 0, sizeof *out);
    int rc = tcb_config_find_sequence(cfg, dataset, sequence, &d, &s, err);
    if (!rc) rc = tcb_run_check_root(cfg, d, err);
    return rc ? rc : tcb_harness_load_sequence(cfg, d, s, NULL, out, err);
}

int tcb_harness_split_path(const tcb_config *cfg, const tcb_dataset_spec *d, const tcb_sequence_spec *s,
                           char *path, size_t size, tcb_error *err)
{
    return tcb_path_join(path, size, err, "%s/%s/%s.json", cfg->splits_dir, d->name, s->name);
}

int tcb_harness_obtain_split(const tcb_config *cfg, const tcb_dataset_spec *d,
                             const tcb_sequence_spec *s, const tcb_sequence *seq, char *path,
                             size_t size, tcb_split *split, tcb_error *err)
{
    int rc = tcb_harness_split_path(cfg, d, s, path, size, err);
    if (rc) return rc;
    return tcb_split_obtain(path, d->name, s->name, s->role, seq->n_frames, seq->blocks, seq->n_blocks,
                            cfg->eval_pairs, cfg->split_seed, split, err);
}

int tcb_harness_obtain_clips(const tcb_config *cfg, const tcb_dataset_spec *d,
                             const tcb_sequence_spec *s, const tcb_sequence *seq, char *path,
                             size_t size, tcb_split *clips, tcb_error *err)
{
    int rc = tcb_path_join(path, size, err, "%s/%s/%s.clips.json", cfg->splits_dir, d->name, s->name);
    if (rc) return rc;
    return tcb_clips_obtain(path, d->name, s->name, s->role, seq->n_frames, seq->blocks, seq->n_blocks,
                            cfg->eval_clips, cfg->split_seed, clips, err);
}

int tcb_harness_work_paths(const char *run_dir, const char *dataset, const char *sequence,
                           const char *label, int seed, char *work, char *ckpt, tcb_error *err)
{
    int rc = tcb_path_join(work, TCB_PATH_MAX, err, "%s/work/%s/%s/%s/seed_%d", run_dir, dataset,
                           sequence, label, seed);
    if (!rc) rc = tcb_path_join(ckpt, TCB_PATH_MAX, err, "%s/model.ckpt", work);
    return rc;
}

/* An existing result (ok or diverged: a diverged training is the method's
 * result) is kept only if it was made with the same method, params and
 * split; otherwise the results directory would mix settings. A failed cell
 * (a crash, a time-out, bad output: no result) is computed again, *keep 0.
 * (The split's path is not compared: the same split may be reached through
 * another working directory.) */
static int check_existing(const char *path, const tcb_method_spec *m, const tcb_split *split,
                          const tcb_split *clips, int *keep, tcb_error *err)
{
    tcb_cell_result c;
    int rc = tcb_cell_load(path, &c, err);
    if (rc) {
        tcb_error_prefix(err, "cannot resume (rerun with --force to recompute): ");
        return rc;
    }
    const char *what = c.status == TCB_CELL_FAILED                   ? NULL
                       : strcmp(c.method_impl, m->method) != 0     ? "method"
                       : strcmp(c.params_json, m->params_json) != 0 ? "params"
                       : c.split_seed != split->seed               ? "split seed"
                       : c.status == TCB_CELL_OK && c.n_pairs != split->n_pairs
                           ? "number of pairs"
                       : c.status == TCB_CELL_OK && c.n_clips != (clips ? clips->n_clips : 0)
                           ? "number of clips"
                           : NULL;
    *keep = c.status != TCB_CELL_FAILED;
    tcb_cell_free(&c);
    if (!what) return TCB_OK;
    return tcb_fail(err, TCB_ERR_INPUT,
                    "%s: was computed with another %s than the config's; rerun with --force to "
                    "recompute, or use a new --out",
                    path, what);
}

/* Shared by every cell of one sequence. */
typedef struct seq_ctx {
    const tcb_dataset_spec *dataset;
    const tcb_sequence *seq;
    const tcb_split *split;     /* n_pairs 0 when the protocol has no pairs */
    const char *split_path;
    const tcb_split *clips;     /* NULL when the protocol has no clips */
    const char *clips_path;
    double load_s;
} seq_ctx;

/* A failed cell of this run, "LABEL: MESSAGE" in the run's list of them. */
static int note_failure(tcb_run_stats *stats, const char *label, const char *message, tcb_error *err)
{
    size_t used = stats->failures ? strlen(stats->failures) : 0, add = strlen(label) + strlen(message) + 4;
    char *grown = realloc(stats->failures, used + add);
    if (!grown) return tcb_fail(err, TCB_ERR_NOMEM, "out of memory");
    snprintf(grown + used, add, "%s: %s\n", label, message);
    stats->failures = grown;
    stats->cells_failed++;
    return TCB_OK;
}

/* The cell under `lock`; its progress goes to the run's reporter and to
 * the lock, where `tcbench status` reads it. */
static int run_cell(const run_state *st, const seq_ctx *sc, const tcb_method_spec *m, int seed,
                    const char *cell_path, tcb_cell_lock *lock, tcb_error *err)
{
    tcb_lock_reporter via_lock;
    char work[TCB_PATH_MAX], ckpt[TCB_PATH_MAX];
    int rc = tcb_harness_work_paths(st->run_dir, sc->dataset->name, sc->seq->name, m->label, seed,
                                    work, ckpt, err);
    if (!rc) rc = tcb_mkdirs(work, err);
    if (!rc) rc = prepare_work_dir(work, st->opts->force, err);
    if (rc) return rc;
    tcb_remove_stale_temps_of(cell_path); /* a resumed run leaves no debris a finished one would not */
    tcb_cell_job job = {
        .seq = sc->seq,
        .split = sc->split,
        .split_path = sc->split_path,
        .dataset = sc->dataset,
        .method = m,
        .ops = tcb_registry_find(m->method),
        .seed = seed,
        .threads = st->cfg->threads,
        .reuse_checkpoint = !st->opts->force,
        .work_dir = work,
        .checkpoint = ckpt,
        .git_revision = st->git_revision,
        .load_s = sc->load_s,
        .reporter = tcb_lock_reporter_make(&via_lock, lock, &st->opts->reporter),
        .interrupted = st->opts->interrupted,
        .interrupt_arg = st->opts->interrupt_arg,
        .clips = sc->clips,
        .clips_path = sc->clips_path,
        .surface_samples = st->cfg->surface_samples,
        .recon_frame = st->cfg->recon_frame,
    };
    char label[TCB_CELL_LABEL_MAX];
    tcb_cell_label(label, sizeof label, sc->dataset->name, sc->seq->name, m->label, seed);
    tcb_cell_result cell;
    rc = tcb_cell_run(&job, &cell, err);
    if (rc) {
        tcb_error_prefix(err, "%s: ", label);
        return rc;
    }
    rc = tcb_cell_save(cell_path, &cell, err);
    if (!rc && cell.status != TCB_CELL_OK)
        tcb_report_log(&st->opts->reporter, TCB_LOG_WARN, "%s %s: %s", label,
                       tcb_cell_status_name(cell.status), cell.message);
    if (!rc && cell.status == TCB_CELL_FAILED) rc = note_failure(st->stats, label, cell.message, err);
    if (!rc) st->stats->cells_done++;
    if (!rc) st->stats->cells_diverged += cell.status == TCB_CELL_DIVERGED;
    tcb_cell_free(&cell);
    return rc;
}

/* A finished cell's lock left by a process killed between writing the cell
 * and releasing the lock: taken over and released (a live holder's is left
 * alone), so no lock outlives its run. */
static int clear_stale_lock(const run_state *st, const char *path, tcb_error *err)
{
    tcb_lock_info holder;
    if (tcb_cell_lock_holder(path, &holder)) return TCB_OK;
    tcb_cell_lock lock;
    char note[512];
    double timeout = tcb_run_lock_timeout(st->opts);
    int rc = tcb_cell_lock_acquire(&lock, path, timeout, &holder, note, sizeof note, err);
    tcb_cell_lock_release(&lock);
    return rc;
}

/* *keep: the cell file at `path` holds a result this run keeps (counted
 * as already done); 0 when there is none or it failed. */
static int kept_result(const run_state *st, const tcb_method_spec *m, const seq_ctx *sc, const char *path, int *keep,
                       tcb_error *err)
{
    *keep = 0;
    if (st->opts->force || !tcb_is_file(path)) return TCB_OK;
    int rc = check_existing(path, m, sc->split, sc->clips, keep, err);
    if (!rc && *keep) st->stats->cells_skipped++;
    if (!rc && *keep) rc = clear_stale_lock(st, path, err);
    return rc;
}

/* A finished cell is skipped; any other (a failed one too) is computed
 * under its lock, unless another live process holds that (it is then left
 * to it). The lock is taken before a look at the cell file settles
 * anything, since the holder may finish it meanwhile. */
static int claim_and_run(const run_state *st, const seq_ctx *sc, const tcb_method_spec *m, int seed,
                         const char *path, tcb_error *err)
{
    int keep;
    int rc = kept_result(st, m, sc, path, &keep, err);
    if (rc || keep) return rc;
    tcb_cell_lock lock;
    tcb_lock_info holder;
    char note[512], label[TCB_CELL_LABEL_MAX];
    double timeout = tcb_run_lock_timeout(st->opts);
    tcb_cell_label(label, sizeof label, sc->dataset->name, sc->seq->name, m->label, seed);
    rc = tcb_cell_lock_acquire(&lock, path, timeout, &holder, note, sizeof note, err);
    if (rc) return rc;
    if (!lock.held) {
        st->stats->cells_busy++;
        tcb_report_log(&st->opts->reporter, TCB_LOG_INFO, "%s: running in %s pid %ld (heartbeat %.0f s ago), left to it",
                       label, holder.host, holder.pid, holder.heartbeat_age_s);
        return TCB_OK;
    }
    if (note[0]) tcb_report_log(&st->opts->reporter, TCB_LOG_WARN, "%s: %s", label, note);
    rc = kept_result(st, m, sc, path, &keep, err);
    if (!rc && !keep) rc = run_cell(st, sc, m, seed, path, &lock, err);
    tcb_cell_lock_release(&lock);
    return rc;
}

/* The cell with this id and method is one the options ask for, of a
 * method the run directory accepts. */
static int cell_wanted(const run_state *st, int id, const tcb_method_spec *m)
{
    const tcb_run_opts *opts = st->opts;
    return !st->refused[m - st->cfg->methods] && tcb_run_selected(opts, m) && (!opts->cells || opts->cells[id]);
}

/* Whether any cell of the sequence whose cells start at `first` is wanted:
 * one that is not is never loaded. */
static int sequence_wanted(const run_state *st, const tcb_dataset_spec *d, int first)
{
    int id = first;
    for (int k = 0; k < st->cfg->n_methods; k++) {
        const tcb_method_spec *m = &st->cfg->methods[k];
        if (!tcb_method_runs_on(m, d->name)) continue;
        for (int s = 0; s < m->n_seeds; s++, id++)
            if (cell_wanted(st, id, m)) return 1;
    }
    return 0;
}

/* The sequence's cells, ids from `first` on (grid order, harness/grid.c). */
static int run_cells(const run_state *st, const seq_ctx *sc, int first, tcb_error *err)
{
    const tcb_config *cfg = st->cfg;
    int id = first;
    for (int k = 0; k < cfg->n_methods; k++) {
        const tcb_method_spec *m = &cfg->methods[k];
        if (!tcb_method_runs_on(m, sc->dataset->name)) continue;
        for (int s = 0; s < m->n_seeds; s++, id++) {
            if (!cell_wanted(st, id, m)) continue;
            if (st->opts->interrupted && st->opts->interrupted(st->opts->interrupt_arg))
                return tcb_fail(err, TCB_ERR_INTERRUPTED, "stopped before cell %d", id);
            char path[TCB_PATH_MAX];
            int rc = tcb_cell_path(path, sizeof path, st->run_dir, sc->dataset->name,
                                   sc->seq->name, m->label, m->seeds[s], err);
            st->stats->cells_total++;
            if (!rc) rc = claim_and_run(st, sc, m, m->seeds[s], path, err);
            if (rc) return rc;
        }
    }
    return TCB_OK;
}

static int run_sequence(const run_state *st, const tcb_dataset_spec *d, const tcb_sequence_spec *s, int first,
                        tcb_error *err)
{
    if (!sequence_wanted(st, d, first)) return TCB_OK;
    tcb_sequence seq = {0};
    tcb_split split = {0}, clips = {0};
    char split_path[TCB_PATH_MAX], clips_path[TCB_PATH_MAX] = "";
    double t0 = tcb_now_seconds();
    tcb_report_log(&st->opts->reporter, TCB_LOG_INFO, "%s/%s: loading", d->name, s->name);
    int rc = tcb_harness_load_sequence(st->cfg, d, s, &st->opts->reporter, &seq, err);
    if (rc) return rc;
    int with_clips = st->cfg->protocols & TCB_PROTOCOL_CLIPS;
    seq_ctx sc = {d, &seq, &split, split_path, with_clips ? &clips : NULL, clips_path, tcb_now_seconds() - t0};
    rc = tcb_harness_obtain_split(st->cfg, d, s, &seq, split_path, sizeof split_path, &split, err);
    /* Clips only: the cells score no pairs (the pairs' split is still the
     * sequence's, named in the cells). */
    if (!rc && !(st->cfg->protocols & TCB_PROTOCOL_PAIRS)) split.n_pairs = 0;
    if (!rc && with_clips)
        rc = tcb_harness_obtain_clips(st->cfg, d, s, &seq, clips_path, sizeof clips_path, &clips, err);
    if (!rc) rc = run_cells(st, &sc, first, err);
    tcb_split_free(&split);
    tcb_split_free(&clips);
    tcb_sequence_free(&seq);
    return rc;
}

int tcb_run_root_missing(const tcb_dataset_spec *d)
{
    return d->source != TCB_SOURCE_SYNTHETIC && !tcb_is_dir(d->root);
}

void tcb_run_missing_root_text(const tcb_dataset_spec *d, char *out, size_t size)
{
    char var[128];
    tcb_config_root_env_name(d->name, var, sizeof var);
    if (d->root[0]) snprintf(out, size, "%s not found", d->root);
    else snprintf(out, size, "no root given (--root %s=DIR or %s)", d->name, var);
}

int tcb_run_check_root(const tcb_config *cfg, const tcb_dataset_spec *d, tcb_error *err)
{
    if (!tcb_run_root_missing(d)) return TCB_OK;
    char why[TCB_PATH_MAX + 64];
    tcb_run_missing_root_text(d, why, sizeof why);
    return tcb_fail(err, TCB_ERR_INPUT, "%s: dataset %s: %s", cfg->path, d->name, why);
}

/* Missing data is found before any cell runs, not hours into the run. */
static int check_roots(const tcb_config *cfg, tcb_error *err)
{
    for (int k = 0; k < cfg->n_datasets; k++)
        if (!cfg->datasets[k].optional && tcb_run_root_missing(&cfg->datasets[k])) {
            const tcb_dataset_spec *d = &cfg->datasets[k];
            char why[TCB_PATH_MAX + 64];
            tcb_run_missing_root_text(d, why, sizeof why);
            if (d->root[0])
                return tcb_fail(err, TCB_ERR_IO, "%s: datasets[%d].root: %s: no such directory",
                                cfg->path, k, d->root);
            return tcb_fail(err, TCB_ERR_INPUT, "%s: datasets[%d] (%s): %s", cfg->path, k, d->name, why);
        }
    return TCB_OK;
}

static int run_grid(const run_state *st, tcb_error *err)
{
    const tcb_config *cfg = st->cfg;
    int rc = TCB_OK;
    for (int k = 0, first = 0; k < cfg->n_datasets && !rc; k++) {
        const tcb_dataset_spec *d = &cfg->datasets[k];
        int per_sequence = tcb_grid_cells_per_sequence(cfg, d);
        if (tcb_run_root_missing(d)) {
            /* A warning, not info: a silently shorter table would mislead. */
            char why[TCB_PATH_MAX + 64];
            tcb_run_missing_root_text(d, why, sizeof why);
            tcb_report_log(&st->opts->reporter, TCB_LOG_WARN, "dataset %s skipped: %s (optional)", d->name, why);
        }
        for (int s = 0; s < d->n_sequences && !rc && !tcb_run_root_missing(d); s++)
            rc = run_sequence(st, d, &d->sequences[s], first + s * per_sequence, err);
        first += d->n_sequences * per_sequence;
    }
    return rc;
}

int tcb_run(const tcb_config *cfg, const tcb_run_opts *opts, tcb_run_stats *stats,
            tcb_error *err)
{
    memset(stats, 0, sizeof *stats);
    unsigned char *refused = calloc((size_t)cfg->n_methods + 1, 1);
    if (!refused) return tcb_fail(err, TCB_ERR_NOMEM, "out of memory");
    run_state st = {cfg, opts, opts->output ? opts->output : cfg->output, "", stats, refused};
    tcb_error refusal = {0};
    int rc = tcb_harness_load_plugins(cfg, err);
    if (!rc) rc = tcb_run_check_methods(cfg, opts, err);
    if (!rc) rc = check_roots(cfg, err);
    if (!rc) rc = tcb_run_dir_claim_methods(cfg, st.run_dir, opts, refused, &refusal, err);
    /* Said first too, so that the cells it leaves out are not waited for. */
    if (!rc && refusal.code)
        tcb_report_log(&opts->reporter, TCB_LOG_WARN, "the run directory refuses some methods (why: at the end); the "
                       "others run");
    if (!rc) tcb_git_revision(st.git_revision, sizeof st.git_revision);
    if (!rc) rc = run_grid(&st, err);
    free(refused);
    if (!rc && refusal.code) {
        *err = refusal;
        rc = refusal.code;
        stats->refused = 1;
    }
    return rc;
}

void tcb_run_stats_free(tcb_run_stats *stats)
{
    free(stats->failures);
    stats->failures = NULL;
}
