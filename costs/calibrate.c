/* `tcbench calibrate`: the costs the dry run prices cells with, measured on
 * this machine (costs/calibration.h).
 *
 * Every registered method with train_steps or units, at each of its
 * presets (one without presets: once, created with "{}") and each thread
 * count asked, is one measurement. Its share of the budget (what is left,
 * over the measurements left) is split between its steps, its surface
 * frames and each unit: the steps are a warm-up step, then steps while
 * their part lasts, at least one and at most MAX_STEPS, then a few
 * evaluation pairs, which also time the harness's scoring; for a method
 * with a surface the reconstruction metrics of frames while their part
 * lasts, at least one; each unit is an untimed run, then runs while its
 * part lasts, at least one. A measurement whose warm-ups and single runs
 * exceed its share overruns the budget, which the closing line says.
 *
 * On a config's sequence (on_config: o->methods set) only the units of the config's
 * methods and the harness's scoring of a pair are measured, on that
 * sequence: what they cost depends on the shape as much as on the counts
 * the calibration sequence's costs are scaled by (docs/cluster.md); a
 * training step does not (it draws the same number of points from any
 * sequence). */
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "costs/calibrate.h"
#include "costs/calibration.h"
#include "costs/step_timing.h"
#include "tcb/fsutil.h"
#include "tcb/registry.h"
#include "tcb/sysinfo.h"

enum {
    MAX_STEPS = 50, QUICK_MAX_STEPS = 5, EVAL_PAIRS = 6, QUICK_EVAL_PAIRS = 1,
    MAX_UNIT_RUNS = 10, QUICK_UNIT_RUNS = 2, SURFACE_FRAMES = 3, QUICK_SURFACE_FRAMES = 1,
    /* a config's sequence's scoring: its cost varies with the pair (how far
     * the no-model prediction lies from the truth), so more of them */
    SEQUENCE_SCORE_PAIRS = 32, QUICK_SEQUENCE_SCORE_PAIRS = 8
};

typedef struct measurement {
    const tcb_method_ops *ops;
    const char *preset;
    int threads;
} measurement;

static int has_presets(const tcb_method_ops *ops)
{
    return ops->abi_version >= 5 && ops->presets && ops->presets[0];
}

static int has_steps(const tcb_method_ops *ops)
{
    return has_presets(ops) && ops->train_steps;
}

static int n_units(const tcb_method_ops *ops)
{
    int n = 0;
    while (ops->abi_version >= 6 && ops->run_unit && ops->units && ops->units[n]) n++;
    return n;
}

/* Appends ops's measurements (its presets, or o->preset, x the thread
 * counts; a method without presets: "") to m unless NULL; returns the
 * presets. */
static int plan_method(const tcb_calibrate_opts *o, const tcb_method_ops *ops, measurement *m, int *n)
{
    static const char *const no_presets[] = {"", NULL};
    const char *const *presets = has_presets(ops) ? ops->presets : no_presets;
    int found = 0;
    for (int p = 0; presets[p]; p++) {
        if (o->preset && strcmp(o->preset, presets[p])) continue;
        found++;
        for (int t = 0; m && t < o->n_threads; t++) m[(*n)++] = (measurement){ops, presets[p], o->threads[t]};
    }
    return found;
}

/* A calibration of a config's sequence (`tcbench calibrate CONFIG`). */
static int on_config(const tcb_calibrate_opts *o) { return o->methods != NULL; }

/* Whether ops is measured: it has costs to measure (on a config's
 * sequence: units, and it is one of the config's methods), and --only
 * names it or nothing. */
static int measured(const tcb_calibrate_opts *o, const tcb_method_ops *ops)
{
    if (o->method && strcmp(o->method, ops->name)) return 0;
    if (!on_config(o)) return has_steps(ops) || n_units(ops);
    int listed = o->n_methods == 0;
    for (int k = 0; k < o->n_methods && !listed; k++) listed = !strcmp(o->methods[k], ops->name);
    return listed && n_units(ops);
}

/* The measurements, in registry order; with m NULL only counted into *n.
 * --only or --preset naming nothing measurable is bad input. */
static int plan(const tcb_calibrate_opts *o, measurement *m, int *n, tcb_error *err)
{
    int methods = 0, presets = 0, counted = 0;
    for (int k = 0; k < tcb_registry_count(); k++) {
        const tcb_method_ops *ops = tcb_registry_get(k);
        if (!measured(o, ops)) continue;
        methods++;
        presets += plan_method(o, ops, m, &counted);
    }
    if (on_config(o) && !methods && o->method)
        return tcb_fail(err, TCB_ERR_INPUT, "calibrate: --only %s: not a method of the config with units to measure "
                        "on its sequences", o->method);
    if (o->method && !methods)
        return tcb_fail(err, TCB_ERR_INPUT, "calibrate: --only %s: no method of that name has costs to measure "
                        "(training steps or units)", o->method);
    if (o->preset && !presets)
        return tcb_fail(err, TCB_ERR_INPUT, "calibrate: --preset %s: no preset of that name%s%s", o->preset,
                        o->method ? " in " : "", o->method ? o->method : "");
    *n = m ? counted : presets * o->n_threads;
    return TCB_OK;
}

/* The costs of one measurement into cal; the pairs' scoring summed into
 * score[threads index]. */
typedef struct session {
    const tcb_calibrate_opts *o;
    const tcb_sequence *seq;
    tcb_calibration *cal;
    double *score_s;
    int *score_n;
    FILE *out;
} session;

static int add(tcb_calibration *cal, tcb_cost_kind kind, const measurement *m, double s, int samples, tcb_error *err)
{
    tcb_cost_entry e = {.kind = kind, .threads = m->threads, .samples = samples, .seconds = s};
    snprintf(e.method, sizeof e.method, "%s", m->ops->name);
    snprintf(e.preset, sizeof e.preset, "%s", m->preset);
    return tcb_calibration_add(cal, &e, err);
}

static int surface_measured(const session *s, const measurement *m)
{
    return tcb_method_has_surface(m->ops) && s->o->surface_samples > 0;
}

/* The reconstruction metrics of a few frames (a method with a surface). */
static int measure_surface(const session *s, const measurement *m, void *self, double budget_s, tcb_error *err)
{
    tcb_step_timing t;
    double mesh_s;
    int rc = tcb_time_surface_frames(m->ops, self, s->seq, s->o->quick ? QUICK_SURFACE_FRAMES : SURFACE_FRAMES,
                                     budget_s, s->o->surface_samples, &t, &mesh_s, err);
    /* the harness's part scales with the samples, the method's surface not */
    if (!rc && !(rc = add(s->cal, TCB_COST_SURFACE_FRAME, m, t.step_s, t.steps, err)))
        s->cal->entries[s->cal->n - 1].size = s->o->surface_samples;
    if (!rc) rc = add(s->cal, TCB_COST_SURFACE_MESH, m, mesh_s, t.steps, err);
    if (!rc) fprintf(s->out, " %.2f s/surface frame (%.2f s its mesh)", t.step_s + mesh_s, mesh_s);
    return rc;
}

/* The steps and the evaluation pairs; the pairs' scoring summed into
 * s->score_*[t_index]. */
static int measure_steps(const session *s, const measurement *m, void *self, int t_index, double budget_s,
                         tcb_error *err)
{
    const tcb_calibrate_opts *o = s->o;
    tcb_fit_ctx ctx = {.seed = 0, .n_threads = m->threads};
    tcb_step_timing t;
    double method_s = 0, score_s = 0;
    int pairs = o->quick ? QUICK_EVAL_PAIRS : EVAL_PAIRS;
    int rc = tcb_time_train_steps(m->ops, self, s->seq, &ctx, o->quick ? QUICK_MAX_STEPS : MAX_STEPS, budget_s, &t,
                                  err);
    if (!rc) rc = tcb_time_eval_pairs(m->ops, self, s->seq, pairs, &method_s, &score_s, err);
    if (!rc) rc = add(s->cal, TCB_COST_STEP, m, t.step_s, t.steps, err);
    if (!rc) rc = add(s->cal, TCB_COST_EVAL_PAIR, m, method_s, pairs, err);
    if (rc) return rc;
    s->score_s[t_index] += score_s * pairs, s->score_n[t_index] += pairs;
    fprintf(s->out, "%9.1f ms/step (%2d steps after a %.1f s warm-up) %8.1f ms/pair", t.step_s * 1e3, t.steps,
            t.first_s, method_s * 1e3);
    return TCB_OK;
}

/* Unit k of the method: its seconds per run. */
static int measure_unit(const session *s, const measurement *m, void *self, int k, double budget_s, tcb_error *err)
{
    tcb_fit_ctx ctx = {.seed = 0, .n_threads = m->threads};
    tcb_step_timing t;
    int rc = tcb_time_unit(m->ops, self, s->seq, &ctx, k, s->o->quick ? QUICK_UNIT_RUNS : MAX_UNIT_RUNS, budget_s, &t,
                           err);
    tcb_cost_entry *e = !rc && !(rc = add(s->cal, TCB_COST_UNIT, m, t.step_s, t.steps, err))
                            ? &s->cal->entries[s->cal->n - 1] : NULL;
    if (e) snprintf(e->unit, sizeof e->unit, "%s", m->ops->units[k]);
    if (e && on_config(s->o)) {
        snprintf(e->sequence, sizeof e->sequence, "%s", s->o->sequence_name);
        e->vertices = s->seq->n_verts;
    }
    if (rc) tcb_error_prefix(err, "unit %s: ", m->ops->units[k]);
    else fprintf(s->out, " %s %.3g s", m->ops->units[k], t.step_s);
    return rc;
}

static int measure(const session *s, const measurement *m, int t_index, double share, tcb_error *err)
{
    char params[128];
    snprintf(params, sizeof params, m->preset[0] ? "{\"preset\": \"%s\"}" : "{}", m->preset);
    void *self;
    int rc = m->ops->create(params, &self, err);
    if (rc) return rc;
    int units = n_units(m->ops), steps = has_steps(m->ops) && !on_config(s->o);
    int surface = steps && surface_measured(s, m);
    double part = 0.8 * share / (steps + surface + units);
    if (steps) rc = measure_steps(s, m, self, t_index, part, err);
    if (!rc && surface) rc = measure_surface(s, m, self, part, err);
    for (int k = 0; !rc && k < units; k++) rc = measure_unit(s, m, self, k, part, err);
    m->ops->destroy(self);
    if (!rc) fprintf(s->out, "\n");
    return rc;
}

static int thread_index(const tcb_calibrate_opts *o, int threads)
{
    int k = 0;
    while (o->threads[k] != threads) k++;
    return k;
}

/* The harness's scoring of pairs of a config's sequence at each thread
 * count, with no method (the source frame's positions: what the nearest
 * baseline predicts), into s->score_*. */
static int measure_scoring(const session *s, tcb_error *err)
{
    int pairs = s->o->quick ? QUICK_SEQUENCE_SCORE_PAIRS : SEQUENCE_SCORE_PAIRS;
    for (int t = 0; t < s->o->n_threads; t++) {
        double method_s, score_s;
        omp_set_num_threads(s->o->threads[t]);
        int rc = tcb_time_eval_pairs(NULL, NULL, s->seq, pairs, &method_s, &score_s, err);
        if (rc) return rc;
        s->score_s[t] += score_s * pairs, s->score_n[t] += pairs;
    }
    return TCB_OK;
}

/* Every measurement, each announced before it starts. */
static int measure_all(const session *s, const measurement *m, int n, tcb_error *err)
{
    double t0 = tcb_now_seconds();
    for (int k = 0; k < n; k++) {
        double left = s->o->budget_s - (tcb_now_seconds() - t0);
        fprintf(s->out, "[%2d/%d] %-9s %-6s %2d thread%s", k + 1, n, m[k].ops->name, m[k].preset, m[k].threads,
                m[k].threads == 1 ? " " : "s");
        fflush(s->out);
        int rc = measure(s, &m[k], thread_index(s->o, m[k].threads), left / (n - k), err);
        if (rc) {
            fprintf(s->out, "failed\n");
            tcb_error_prefix(err, "calibrate %s%s%s, %d threads: ", m[k].ops->name, m[k].preset[0] ? " preset " : "",
                             m[k].preset, m[k].threads);
            return rc;
        }
    }
    int rc = on_config(s->o) ? measure_scoring(s, err) : TCB_OK;
    if (rc) return rc;
    for (int t = 0; t < s->o->n_threads; t++) {
        tcb_cost_entry e = {.kind = TCB_COST_SCORE_PAIR, .threads = s->o->threads[t], .samples = s->score_n[t]};
        e.seconds = s->score_n[t] ? s->score_s[t] / s->score_n[t] : 0;
        if (on_config(s->o)) snprintf(e.sequence, sizeof e.sequence, "%s", s->o->sequence_name);
        e.vertices = on_config(s->o) ? s->seq->n_verts : 0;
        rc = s->score_n[t] ? tcb_calibration_add(s->cal, &e, err) : TCB_OK;
        if (rc) return rc;
        if (s->score_n[t])
            fprintf(s->out, "scoring a pair (projection, metrics, geodesic error), %d thread%s: %.1f ms at %d vertices\n",
                    e.threads, e.threads == 1 ? "" : "s", e.seconds * 1e3, s->seq->n_verts);
    }
    return TCB_OK;
}

/* Summaries "CPU, N cores, load L" of one machine: the same but for the load. */
static int same_machine(const char *a, const char *b)
{
    const char *la = strstr(a, ", load "), *lb = strstr(b, ", load ");
    size_t na = la ? (size_t)(la - a) : strlen(a), nb = lb ? (size_t)(lb - b) : strlen(b);
    return na == nb && !strncmp(a, b, na);
}

/* The measured costs, and those of an earlier calibration of this very
 * machine at path that were not measured again (--only, --preset add to
 * it); a file of another machine is replaced. */
static int merge_earlier(const char *path, tcb_calibration *cal, FILE *out, tcb_error *err)
{
    char *text;
    size_t len;
    tcb_calibration old;
    tcb_error ignored = {0};
    if (!tcb_is_file(path) || tcb_read_file(path, &text, &len, &ignored)) return TCB_OK;
    int rc = tcb_calibration_parse(text, path, &old, &ignored);
    free(text);
    if (rc || !same_machine(old.machine, cal->machine) || old.n_verts != cal->n_verts ||
        old.n_frames != cal->n_frames) {
        if (!rc) fprintf(out, "replacing %s (made on %s)\n", path, old.machine);
        if (!rc) tcb_calibration_free(&old);
        return TCB_OK;
    }
    int measured = cal->n;
    for (int k = 0; !rc && k < old.n; k++) {
        const tcb_cost_entry *e = &old.entries[k];
        int again = 0;
        for (int q = 0; q < measured && !again; q++) {
            const tcb_cost_entry *f = &cal->entries[q];
            again = f->kind == e->kind && f->threads == e->threads && !strcmp(f->method, e->method) &&
                    !strcmp(f->preset, e->preset) && !strcmp(f->unit, e->unit) && !strcmp(f->sequence, e->sequence);
        }
        if (!again) rc = tcb_calibration_add(cal, e, err);
    }
    tcb_calibration_free(&old);
    return rc;
}

static int write_out(const tcb_calibrate_opts *o, tcb_calibration *cal, FILE *out, tcb_error *err)
{
    char dir[4096];
    snprintf(dir, sizeof dir, "%s", o->out_path);
    char *slash = strrchr(dir, '/');
    int rc = slash && slash != dir ? (*slash = '\0', tcb_mkdirs(dir, err)) : TCB_OK;
    if (!rc) rc = merge_earlier(o->out_path, cal, out, err);
    if (!rc) rc = tcb_calibration_write(cal, o->out_path, err);
    return rc;
}

int tcb_calibrate_check(const tcb_calibrate_opts *o, tcb_error *err)
{
    int n;
    return plan(o, NULL, &n, err);
}

/* The first line: what is measured, where, in what budget. */
static void announce(const tcb_calibrate_opts *o, const char *machine, int n, FILE *out)
{
    if (on_config(o))
        fprintf(out, "calibrating on %s: %d measurements of units, and the scoring of pairs, on %s (%d frames, %d "
                "vertices) in a budget of %.0f s\n", machine, n, o->sequence_name, o->sequence->n_frames,
                o->sequence->n_verts, o->budget_s);
    else
        fprintf(out, "calibrating on %s: %d measurements in a budget of %.0f s (%s)\n", machine, n, o->budget_s,
                o->quick ? "quick: coarse" : "a warm-up step, then steps while the budget lasts");
}

int tcb_calibrate(const tcb_calibrate_opts *o, FILE *out, tcb_error *err)
{
    if (on_config(o) && !o->sequence)
        return tcb_fail(err, TCB_ERR_INTERNAL, "calibrate: a config's methods without its sequence");
    int n = 0;
    int rc = plan(o, NULL, &n, err);
    measurement *m = rc ? NULL : calloc(n ? (size_t)n : 1, sizeof *m);
    double *score_s = rc ? NULL : calloc((size_t)o->n_threads, sizeof *score_s);
    int *score_n = rc ? NULL : calloc((size_t)o->n_threads, sizeof *score_n);
    if (!rc && (!m || !score_s || !score_n)) rc = tcb_fail(err, TCB_ERR_NOMEM, "out of memory");
    if (!rc) rc = plan(o, m, &n, err);
    tcb_sequence seq = {0};
    tcb_calibration cal = {0};
    /* the file records the calibration sequence's counts, also when it
     * holds a config's sequence's units: they are of the same machine */
    if (!rc) rc = tcb_calibration_sequence(&seq, err);
    if (!rc && !(cal.machine_json = tcb_machine_describe(cal.machine, sizeof cal.machine)))
        rc = tcb_fail(err, TCB_ERR_NOMEM, "out of memory");
    if (!rc) {
        cal.n_verts = seq.n_verts, cal.n_frames = seq.n_frames;
        announce(o, cal.machine, n, out);
    }
    int prev = omp_get_max_threads();
    double t0 = tcb_now_seconds();
    session s = {o, on_config(o) ? o->sequence : &seq, &cal, score_s, score_n, out};
    if (!rc) rc = measure_all(&s, m, n, err);
    omp_set_num_threads(prev);
    double took = tcb_now_seconds() - t0;
    if (!rc) rc = write_out(o, &cal, out, err);
    if (!rc)
        fprintf(out, "took %.0f s%s; wrote %s\n", took, took > 1.1 * o->budget_s ? " (over the budget: a warm-up "
                "and one step of the largest presets exceed their share)" : "", o->out_path);
    tcb_calibration_free(&cal);
    tcb_sequence_free(&seq);
    free(m), free(score_s), free(score_n);
    return rc;
}
