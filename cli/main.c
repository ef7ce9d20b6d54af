/* tcbench — the command-line interface.
 *
 * A thin layer over libtcbench: parse arguments, call the library, print.
 * Data (tables, lists) goes to stdout, status lines and errors to stderr.
 * Every error is one line "tcbench: <message>"; bad usage, bad input and
 * unreadable paths exit 2, other failures 1. */
#include <errno.h>
#include <limits.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "harness/calibration.h"
#include "harness/internal.h"
#include "tcb/tcb.h"

/* ---- options -------------------------------------------------------- */

enum {
    F_OUT, F_ONLY, F_FORCE, F_QUIET, F_REPORT, F_SEED, F_FRAMES, F_SEQUENCE, F_UPDATE,
    F_PLUGIN, F_THREADS, F_VERBOSE, F_SAMPLES, F_PLOT, F_ROOT, F_VARIANT, F_DRY_RUN, F_REFERENCE, F_CELL,
    F_SHARD, F_LOCK_TIMEOUT, F_DATASET, F_PRED, F_NAME, F_HELP,
    F_N_FRAMES, F_STYLE, F_ANY_FRAME, F_RESAMPLES, F_QUICK, F_PRESET, F_BUDGET, F_TASKS, F_COUNT
};
#define BIT(f) (1ull << (f))

static const struct {
    const char *name;
    int takes_value;
} flags[F_COUNT] = {
    [F_OUT] = {"--out", 1},      [F_ONLY] = {"--only", 1},       [F_FORCE] = {"--force", 0},
    [F_QUIET] = {"--quiet", 0},  [F_REPORT] = {"--report", 0},   [F_SEED] = {"--seed", 1},
    [F_FRAMES] = {"--frames", 1}, [F_SEQUENCE] = {"--sequence", 1}, [F_UPDATE] = {"--update", 0},
    [F_PLUGIN] = {"--plugin", 1}, [F_THREADS] = {"--threads", 1}, [F_VERBOSE] = {"--verbose", 0},
    [F_SAMPLES] = {"--samples", 1}, [F_PLOT] = {"--plot", 1}, [F_ROOT] = {"--root", 1},
    [F_VARIANT] = {"--variant", 1}, [F_DRY_RUN] = {"--dry-run", 0}, [F_REFERENCE] = {"--reference", 1},
    [F_CELL] = {"--cell", 1},    [F_SHARD] = {"--shard", 1},   [F_LOCK_TIMEOUT] = {"--lock-timeout", 1},
    [F_DATASET] = {"--dataset", 1}, [F_PRED] = {"--pred", 1},  [F_NAME] = {"--name", 1},
    [F_HELP] = {"--help", 0},    [F_N_FRAMES] = {"--count", 1}, [F_STYLE] = {"--style", 1},
    [F_ANY_FRAME] = {"--any-frame", 0}, [F_RESAMPLES] = {"--resamples", 1},
    [F_QUICK] = {"--quick", 0},  [F_PRESET] = {"--preset", 1}, [F_BUDGET] = {"--budget", 1},
    [F_TASKS] = {"--tasks", 1},
};

#define MAX_PLUGINS 64
#define MAX_ROOTS 16
#define MAX_ARGS 4

typedef struct cli {
    const char *arg[MAX_ARGS];   /* positional arguments */
    int n_args;
    const char *value[F_COUNT];  /* the value of each flag taking one */
    long long num[F_COUNT];      /* ... as an integer, for the flags of int_flags[] */
    int set[F_COUNT];            /* flag given */
    const char *plugins[MAX_PLUGINS];
    int n_plugins;
    tcb_root_override roots[MAX_ROOTS]; /* --root NAME=DIR; dataset points into root_names */
    char root_names[MAX_ROOTS][64];
    int n_roots;
} cli;

typedef struct command {
    const char *name;
    int (*fn)(const cli *c);
    unsigned long long accepts; /* BIT(F_...) of the command's own flags */
    int min_args, max_args;
    const char *arg_names;  /* for "missing ..." messages */
    const char *help;
} command;

static int fail(const tcb_error *err)
{
    fprintf(stderr, "tcbench: %s\n", err->msg);
    return tcb_status_exit_code(err->code);
}

/* Bad usage: names the command and the offending word, exits 2. */
static int usage_error(const char *cmd, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static int usage_error(const char *cmd, const char *fmt, ...)
{
    fprintf(stderr, "tcbench: %s%s", cmd ? cmd : "", cmd ? ": " : "");
    va_list ap;
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fprintf(stderr, " (see 'tcbench %s%s--help')\n", cmd ? cmd : "", cmd ? " " : "");
    return 2;
}

/* The flags that take an integer, and the range each accepts; `cmd` NULL:
 * in every command that takes the flag. The value is checked when the line
 * is parsed, before any command runs, so that a 0, a negative number or a
 * word is never taken for "the default" (--threads 0 was once read so). */
static const struct int_flag {
    int flag;
    const char *cmd;
    long long min, max;
} int_flags[] = {
    {F_THREADS, "calibrate", 1, 0},       /* a list there (min > max: not an integer flag) */
    {F_THREADS, NULL, 1, 1024},
    {F_BUDGET, NULL, 1, 1000000},         /* seconds */
    {F_TASKS, NULL, 1, 1000000},          /* concurrent tasks of a Slurm array */
    {F_SEED, "datasets", 0, LLONG_MAX},  /* a generator's seed, as a config's dataset "seed" */
    {F_SEED, NULL, 0, INT_MAX},           /* a cell's seed, as a config's "seeds" */
    {F_FRAMES, "datasets", 1, 100000},    /* frames per sequence; `frames` takes a list */
    {F_N_FRAMES, NULL, 1, TCB_FRAMES_MAX},
    {F_SAMPLES, NULL, 1, 10000000},
    {F_LOCK_TIMEOUT, NULL, 1, 1000000000},
    {F_RESAMPLES, NULL, 100, 10000000},   /* bootstrap resamples per comparison */
};

static const struct int_flag *int_flag_of(const char *cmd, int f)
{
    for (size_t k = 0; k < sizeof int_flags / sizeof int_flags[0]; k++)
        if (int_flags[k].flag == f && (!int_flags[k].cmd || (cmd && !strcmp(int_flags[k].cmd, cmd))))
            return int_flags[k].min > int_flags[k].max ? NULL : &int_flags[k];
    return NULL;
}

/* s as flag f's integer: strictly a decimal number within the flag's range. */
static int parse_int_flag(const char *cmd, int f, const char *s, long long *out)
{
    const struct int_flag *r = int_flag_of(cmd, f);
    if (!r) return 0;
    char *end;
    errno = 0;
    long long v = strtoll(s, &end, 10);
    if (!*s || *end || errno || v < r->min || v > r->max)
        return usage_error(cmd, "%s: expected an integer from %lld to %lld, got '%s'", flags[f].name, r->min,
                           r->max, s);
    *out = v;
    return 0;
}

/* Flag f's integer (checked by parse_int_flag), or `def` when not given. */
static long long flag_int(const cli *c, int f, long long def) { return c->set[f] ? c->num[f] : def; }

/* ---- commands ------------------------------------------------------- */

/* The config as the command line shapes it: variant, roots, threads (the
 * flag, else Slurm's SLURM_CPUS_PER_TASK, else the config's). */
static int load_config(const cli *c, tcb_config *cfg)
{
    tcb_error err = {0};
    long long threads = flag_int(c, F_THREADS, 0);
    const char *slurm = getenv("SLURM_CPUS_PER_TASK");
    if (!threads && slurm && atoi(slurm) > 0) threads = atoi(slurm);
    tcb_config_opts co = {c->value[F_VARIANT], c->n_roots, c->roots};
    if (tcb_config_load_opts(c->arg[0], &co, cfg, &err)) return fail(&err);
    if (threads > 0) cfg->threads = (int)(threads > 1024 ? 1024 : threads); /* Slurm's may be more */
    return 0;
}

/* --cell and --shard as a mask over the config's cell ids; *mask NULL:
 * every cell. */
static int cell_mask(const cli *c, const tcb_config *cfg, unsigned char **mask)
{
    tcb_error err = {0};
    int n = tcb_grid_count(cfg);
    *mask = NULL;
    if (!c->set[F_CELL] && !c->set[F_SHARD]) return 0;
    if (!(*mask = malloc(n ? (size_t)n : 1))) return fprintf(stderr, "tcbench: out of memory\n"), 1;
    memset(*mask, 1, (size_t)n);
    int rc = c->set[F_CELL] ? tcb_cell_set_parse(c->value[F_CELL], n, *mask, &err) : TCB_OK;
    if (!rc && c->set[F_SHARD]) rc = tcb_shard_parse(c->value[F_SHARD], n, *mask, &err);
    if (!rc) return 0;
    free(*mask);
    *mask = NULL;
    return fail(&err);
}

/* The run's counts, and its failed cells with their messages. */
static void print_counts(const tcb_run_stats *st)
{
    fprintf(stderr, "cells: %d in all, %d computed, %d already done, %d failed", st->cells_total, st->cells_done,
            st->cells_skipped, st->cells_failed);
    if (st->cells_diverged) fprintf(stderr, ", %d diverged", st->cells_diverged);
    if (st->cells_busy) fprintf(stderr, ", %d running in other processes", st->cells_busy);
    fprintf(stderr, "\n");
    if (st->cells_failed)
        fprintf(stderr, "failed cells (no result; a rerun retries them):\n%s", st->failures ? st->failures : "");
}

/* Exit 1 when a cell failed: a table without it is not the run asked for. */
static int finish_run(const cli *c, const char *run_dir, const tcb_run_stats *st)
{
    tcb_error err = {0};
    print_counts(st);
    fprintf(stderr, "results: %s\n", run_dir);
    int rc = st->cells_failed ? 1 : 0;
    if (!c->set[F_REPORT]) {
        fprintf(stderr, "make the report: tcbench report %s\n", run_dir);
        return rc;
    }
    if (tcb_report_write(run_dir, NULL, c->set[F_QUIET] ? NULL : stdout, &err)) return fail(&err);
    fprintf(stderr, "report: %s/report/\n", run_dir);
    return rc;
}

static int cmd_run(const cli *c)
{
    tcb_error err = {0};
    tcb_config cfg;
    unsigned char *mask;
    if (c->set[F_TASKS] && !c->set[F_DRY_RUN]) return usage_error("run", "--tasks applies to --dry-run only");
    int rc = load_config(c, &cfg);
    if (rc) return rc;
    if ((rc = cell_mask(c, &cfg, &mask))) {
        tcb_config_free(&cfg);
        return rc;
    }
    tcb_term_progress tp;
    tcb_term_progress_init(&tp, stderr, c->set[F_QUIET] ? 1 : -1);
    tp.verbose = c->set[F_VERBOSE];
    tcb_stop_signals stop;
    tcb_run_opts opts = {.output = c->value[F_OUT], .only_method = c->value[F_ONLY], .force = c->set[F_FORCE],
                         .reporter = c->set[F_DRY_RUN] ? (tcb_reporter){0} : tcb_term_progress_reporter(&tp),
                         .cells = mask, .lock_timeout_s = (double)flag_int(c, F_LOCK_TIMEOUT, 0),
                         .tasks = (int)flag_int(c, F_TASKS, 0),
                         .interrupted = tcb_stop_signals_requested, .interrupt_arg = &stop};
    /* Before any thread exists, so that every thread blocks the signals. */
    if (tcb_stop_signals_start(&stop)) fprintf(stderr, "tcbench: cannot watch for SIGTERM; a signal kills the run\n");
    tcb_run_stats st = {0};
    rc = c->set[F_DRY_RUN] ? tcb_run_dry(&cfg, &opts, stdout, &err) : tcb_run(&cfg, &opts, &st, &err);
    tcb_term_progress_finish(&tp);
    char run_dir[TCB_PATH_MAX];
    snprintf(run_dir, sizeof run_dir, "%s", opts.output ? opts.output : cfg.output);
    tcb_config_free(&cfg);
    free(mask);
    tcb_stop_signals_end(&stop);
    if (rc && st.refused) print_counts(&st); /* the other methods ran */
    if (!rc && !c->set[F_DRY_RUN]) rc = finish_run(c, run_dir, &st);
    else if (rc) rc = fail(&err);
    tcb_run_stats_free(&st);
    return rc;
}

/* `tcbench status RUN_DIR|CONFIG`: a run directory is read through the
 * config it saved (<run>/config.json, already resolved). */
static int cmd_status(const cli *c)
{
    tcb_error err = {0};
    tcb_config cfg;
    char saved[TCB_PATH_MAX];
    cli resolved = *c;
    if (tcb_is_dir(c->arg[0])) {
        if (tcb_path_join(saved, sizeof saved, &err, "%s/config.json", c->arg[0])) return fail(&err);
        resolved.arg[0] = saved;
        if (!resolved.value[F_OUT]) resolved.value[F_OUT] = c->arg[0];
    }
    int rc = load_config(&resolved, &cfg);
    if (rc) return rc;
    tcb_term_progress tp; /* warnings only (squeue's failure) */
    tcb_term_progress_init(&tp, stderr, 1);
    tcb_run_opts opts = {.output = resolved.value[F_OUT], .reporter = tcb_term_progress_reporter(&tp),
                         .lock_timeout_s = (double)flag_int(&resolved, F_LOCK_TIMEOUT, 0)};
    rc = tcb_run_status(&cfg, &opts, stdout, &err);
    tcb_config_free(&cfg);
    return rc ? fail(&err) : 0;
}

static int cmd_cells(const cli *c)
{
    tcb_error err = {0};
    tcb_config cfg;
    int rc = load_config(c, &cfg);
    if (rc) return rc;
    tcb_run_opts opts = {.output = c->value[F_OUT], .lock_timeout_s = (double)flag_int(c, F_LOCK_TIMEOUT, 0)};
    rc = tcb_run_list_cells(&cfg, &opts, stdout, &err);
    tcb_config_free(&cfg);
    return rc ? fail(&err) : 0;
}

static int cmd_report(const cli *c)
{
    tcb_error err = {0};
    const char *out = c->value[F_OUT];
    if (c->value[F_REFERENCE]) {
        FILE *echo = c->set[F_QUIET] ? NULL : stdout;
        if (tcb_report_reference_resampled(c->arg[0], c->value[F_REFERENCE], out, (int)flag_int(c, F_RESAMPLES, 0),
                                           echo, &err))
            return fail(&err);
        fprintf(stderr, "report: %s/reference_*.{md,tex,csv}\n", out ? out : c->arg[0]);
        return 0;
    }
    if (tcb_report_write_resampled(c->arg[0], out, (int)flag_int(c, F_RESAMPLES, 0), c->set[F_QUIET] ? NULL : stdout,
                                   &err))
        return fail(&err);
    if (out) fprintf(stderr, "report: %s/\n", out);
    else fprintf(stderr, "report: %s/report/\n", c->arg[0]);
    return 0;
}

static int cmd_compare(const cli *c)
{
    tcb_error err = {0};
    if (tcb_compare_run(c->arg[0], c->value[F_DATASET], c->value[F_SEQUENCE], c->arg[1], c->arg[2],
                        (int)flag_int(c, F_RESAMPLES, 0), stdout, &err))
        return fail(&err);
    return 0;
}

static int cmd_methods(const cli *c)
{
    (void)c;
    int wn = 4, wo = 6;
    for (int k = 0; k < tcb_registry_count(); k++) {
        int n = (int)strlen(tcb_registry_get(k)->name), o = (int)strlen(tcb_registry_origin(k));
        wn = n > wn ? n : wn;
        wo = o > wo ? o : wo;
    }
    printf("%-*s  %-*s  %s\n", wn, "NAME", wo, "ORIGIN", "DESCRIPTION");
    for (int k = 0; k < tcb_registry_count(); k++) {
        const tcb_method_ops *m = tcb_registry_get(k);
        printf("%-*s  %-*s  %s\n", wn, m->name, wo, tcb_registry_origin(k),
               m->description ? m->description : "");
    }
    return 0;
}

static int synth_index(const char *name)
{
    for (int k = 0; k < tcb_synth_count(); k++)
        if (strcmp(tcb_synth_name(k), name) == 0) return k;
    return -1;
}

static int datasets_synth(const cli *c)
{
    if (!c->value[F_OUT]) return usage_error("datasets synth", "%s is required", "--out DIR");
    const char *only = c->value[F_SEQUENCE];
    if (only && synth_index(only) < 0)
        return usage_error("datasets synth", "no synthetic sequence named '%s'", only);
    for (int k = 0; k < tcb_synth_count(); k++) {
        const char *name = tcb_synth_name(k);
        if (only && strcmp(only, name) != 0) continue;
        tcb_error err = {0};
        tcb_sequence seq = {0};
        char dir[TCB_PATH_MAX];
        int rc = tcb_path_join(dir, sizeof dir, &err, "%s/%s", c->value[F_OUT], name);
        if (!rc) rc = tcb_synth_generate(name, (uint64_t)flag_int(c, F_SEED, 0), (int)flag_int(c, F_FRAMES, 0), &seq, &err);
        if (!rc) rc = tcb_sequence_write_objdir(&seq, dir, &err);
        if (!rc) fprintf(stderr, "wrote %s/ (%d frames, %d vertices)\n", dir, seq.n_frames, seq.n_verts);
        tcb_sequence_free(&seq);
        if (rc) return fail(&err);
    }
    return 0;
}

static int datasets_align(const cli *c)
{
    if (c->n_args != 2) return usage_error("datasets align", "missing %s", "DIR");
    if (!c->value[F_OUT]) return usage_error("datasets align", "%s is required", "--out FILE");
    if (c->set[F_FRAMES] || c->set[F_SEQUENCE])
        return usage_error("datasets align", "%s applies to 'datasets synth' only",
                           c->set[F_FRAMES] ? "--frames" : "--sequence");
    tcb_align_cmd a = {c->value[F_OUT], c->value[F_PLOT], (int)flag_int(c, F_SAMPLES, TCB_ALIGN_DEFAULT_SAMPLES),
                       (uint64_t)flag_int(c, F_SEED, 0)};
    tcb_error err = {0};
    if (tcb_datasets_align(c->arg[1], &a, &err)) return fail(&err);
    fprintf(stderr, "wrote %s%s%s\n", a.out, a.plot ? " and " : "", a.plot ? a.plot : "");
    return 0;
}

static int datasets_distortion(const cli *c)
{
    if (c->n_args != 2) return usage_error("datasets distortion", "missing %s", "NAME|DIR");
    for (int f = 0; f < F_COUNT; f++)
        if (f != F_PLUGIN && f != F_SEED && f != F_FRAMES && c->set[f])
            return usage_error("datasets distortion", "%s does not apply", flags[f].name);
    tcb_error err = {0};
    if (tcb_datasets_distortion(c->arg[1], (uint64_t)flag_int(c, F_SEED, 0), (int)flag_int(c, F_FRAMES, 0),
                                stdout, &err))
        return fail(&err);
    return 0;
}

static int cmd_datasets(const cli *c)
{
    if (strcmp(c->arg[0], "align") == 0) return datasets_align(c);
    if (strcmp(c->arg[0], "distortion") == 0) return datasets_distortion(c);
    if (c->n_args > 1) return usage_error("datasets", "unexpected argument '%s'", c->arg[1]);
    if (c->set[F_SAMPLES] || c->set[F_PLOT])
        return usage_error("datasets", "%s applies to 'datasets align' only",
                           c->set[F_SAMPLES] ? "--samples" : "--plot");
    if (strcmp(c->arg[0], "synth") == 0) return datasets_synth(c);
    if (strcmp(c->arg[0], "list") != 0)
        return usage_error("datasets", "unknown action '%s' (expected list, synth, align or distortion)", c->arg[0]);
    for (int f = 0; f < F_COUNT; f++)
        if (f != F_PLUGIN && c->set[f])
            return usage_error("datasets list", "%s applies to 'datasets synth' only", flags[f].name);
    for (int k = 0; k < tcb_synth_count(); k++)
        printf("%-20s %s\n", tcb_synth_name(k), tcb_synth_description(k));
    return 0;
}

static int cmd_check(const cli *c)
{
    tcb_error err = {0};
    const char *run = c->arg[0], *baseline = c->arg[1];
    if (c->set[F_UPDATE]) {
        if (tcb_baseline_write(run, baseline, &err)) return fail(&err);
        fprintf(stderr, "baseline written: %s\n", baseline);
        return 0;
    }
    int n_drift = 0;
    if (tcb_check(run, baseline, stdout, &n_drift, &err)) return fail(&err);
    if (!n_drift) return 0;
    fprintf(stderr, "tcbench: %d row%s of %s drifted from %s\n", n_drift, n_drift == 1 ? "" : "s",
            run, baseline);
    return 1;
}

static int cmd_inspect(const cli *c)
{
    long long pair = -1;
    if (strcmp(c->arg[2], "worst") != 0) {
        char *end;
        errno = 0;
        pair = strtoll(c->arg[2], &end, 10);
        if (!*c->arg[2] || *end || errno || pair < 0 || pair > 1000000000)
            return usage_error("inspect", "PAIR: expected a pair index or 'worst', got '%s'",
                               c->arg[2]);
    }
    tcb_term_progress tp;
    tcb_term_progress_init(&tp, stderr, c->set[F_QUIET] ? 1 : -1);
    tcb_inspect_opts o = {c->arg[0], c->arg[1], (int)pair, (int)flag_int(c, F_SEED, -1), c->value[F_SEQUENCE],
                          c->value[F_OUT], (int)flag_int(c, F_THREADS, 0), tcb_term_progress_reporter(&tp)};
    tcb_error err = {0};
    char dir[TCB_PATH_MAX];
    int rc = tcb_inspect(&o, stdout, dir, &err);
    tcb_term_progress_finish(&tp);
    if (rc) return fail(&err);
    fprintf(stderr, "files: %s/\n", dir);
    return 0;
}

/* "0,8,16": distinct checks are the library's, which knows the sequence. */
static int frame_list(const char *s, int *frames, int *n)
{
    *n = 0;
    for (const char *p = s;; p++) {
        char *end;
        errno = 0;
        long v = strtol(p, &end, 10);
        if (end == p || errno || v < 0 || v > 1000000000 || (*end && *end != ',') || *n == TCB_FRAMES_MAX)
            return usage_error("frames", "--frames: expected up to %d frame numbers separated by commas, got '%s'",
                               TCB_FRAMES_MAX, s);
        frames[(*n)++] = (int)v;
        if (!*end) return 0;
        p = end;
    }
}

static int frames_style(const char *s, tcb_frames_style *style)
{
    static const char *const names[] = {"auto", "texture", "transfer"}; /* tcb_frames_style */
    for (int k = 0; k < 3; k++)
        if (strcmp(s ? s : "auto", names[k]) == 0) return *style = (tcb_frames_style)k, 0;
    return usage_error("frames", "--style: expected auto, texture or transfer, got '%s'", s);
}

static int cmd_frames(const cli *c)
{
    int frames[TCB_FRAMES_MAX], n = 0;
    tcb_frames_style style = TCB_FRAMES_AUTO;
    if (c->set[F_FRAMES] && c->set[F_N_FRAMES]) return usage_error("frames", "--frames and --count exclude each other");
    if (c->set[F_FRAMES] && frame_list(c->value[F_FRAMES], frames, &n)) return 2;
    if (frames_style(c->value[F_STYLE], &style)) return 2;
    tcb_term_progress tp;
    tcb_term_progress_init(&tp, stderr, c->set[F_QUIET] ? 1 : -1);
    tcb_frames_opts o = {c->arg[0], c->arg[1], n ? frames : NULL, n, (int)flag_int(c, F_N_FRAMES, 0),
                         (int)flag_int(c, F_SEED, -1), c->value[F_SEQUENCE], c->value[F_OUT],
                         (int)flag_int(c, F_THREADS, 0), style, tcb_term_progress_reporter(&tp)};
    tcb_error err = {0};
    char dir[TCB_PATH_MAX];
    int rc = tcb_frames(&o, stdout, dir, &err);
    tcb_term_progress_finish(&tp);
    if (rc) return fail(&err);
    fprintf(stderr, "files: %s/\n", dir);
    return 0;
}

static int cmd_score(const cli *c)
{
    static const struct { int flag; const char *text; } required[] = {
        {F_DATASET, "--dataset D"}, {F_SEQUENCE, "--sequence S"}, {F_PRED, "--pred DIR|FILE.npz"}, {F_NAME, "--name LABEL"}};
    for (size_t k = 0; k < sizeof required / sizeof required[0]; k++)
        if (!c->value[required[k].flag]) return usage_error("score", "%s is required", required[k].text);
    long long seed = flag_int(c, F_SEED, 0);
    tcb_config cfg;
    int rc = load_config(c, &cfg);
    if (rc) return rc;
    tcb_score_opts o = {c->value[F_DATASET], c->value[F_SEQUENCE], c->value[F_PRED], c->value[F_NAME], (int)seed,
                        c->value[F_OUT], c->set[F_FORCE], c->set[F_ANY_FRAME]};
    tcb_error err = {0};
    char path[TCB_PATH_MAX];
    tcb_summary s;
    rc = tcb_score(&cfg, &o, path, &s, &err);
    tcb_config_free(&cfg);
    if (rc) return fail(&err);
    printf("%s/%s %s: %d pairs, m_sL2 %.2f  rank %.2f  AUC %.2f  CD -\n", o.dataset, o.sequence, o.label,
           s.n_pairs, 1e3 * s.sl2.mean, 1e2 * s.rank.mean, 1e2 * s.auc.mean);
    fprintf(stderr, "cell: %s\n", path);
    return 0;
}

/* calibrate --threads: "1,2,16", kept increasing without repeats. */
static int thread_list(const char *text, int *threads, int max, int *n)
{
    *n = 0;
    for (const char *p = text; *p;) {
        char *end;
        errno = 0;
        long t = strtol(p, &end, 10);
        if (end == p || errno || t < 1 || t > 1024 || (*end && *end != ',') || (*end == ',' && !end[1]))
            return usage_error("calibrate", "--threads: expected thread counts from 1 to 1024 separated by commas, "
                               "got '%s'", text);
        int at = 0;
        while (at < *n && threads[at] < t) at++;
        if (at == *n || threads[at] != t) {
            if (*n == max) return usage_error("calibrate", "--threads: more than %d thread counts", max);
            memmove(threads + at + 1, threads + at, (size_t)(*n - at) * sizeof *threads);
            threads[at] = (int)t, (*n)++;
        }
        p = *end ? end + 1 : end;
    }
    return 0;
}

static int cmd_calibrate(const cli *c)
{
    enum { MAX_COUNTS = 16 };
    char cores[16], user[TCB_PATH_MAX];
    snprintf(cores, sizeof cores, "1,2,%d", tcb_cpu_count());
    int threads[MAX_COUNTS], n = 0;
    int rc = thread_list(c->set[F_THREADS] ? c->value[F_THREADS] : cores, threads, MAX_COUNTS, &n);
    if (rc) return rc;
    tcb_calibration_user_path(user, sizeof user);
    const char *out = c->value[F_OUT] ? c->value[F_OUT] : user;
    if (!out[0]) return usage_error("calibrate", "neither HOME nor XDG_CONFIG_HOME is set: give --out FILE");
    tcb_calibrate_opts o = {threads, n, c->value[F_ONLY], c->value[F_PRESET],
                            (double)flag_int(c, F_BUDGET, c->set[F_QUICK] ? 60 : 600), c->set[F_QUICK],
                            (int)flag_int(c, F_SAMPLES, TCB_DEFAULT_SURFACE_SAMPLES), out};
    tcb_error err = {0};
    return tcb_calibrate(&o, stdout, &err) ? fail(&err) : 0;
}

static int cmd_version(const cli *c)
{
    (void)c;
    char rev[64];
    tcb_git_revision(rev, sizeof rev);
    printf("tcbench %s (git %s)\n", TCB_VERSION, rev);
    return 0;
}

static int cmd_help(const cli *c);

static const command commands[] = {
    {"run", cmd_run,
     BIT(F_OUT) | BIT(F_ONLY) | BIT(F_FORCE) | BIT(F_QUIET) | BIT(F_REPORT) | BIT(F_THREADS) | BIT(F_VERBOSE) |
         BIT(F_ROOT) | BIT(F_VARIANT) | BIT(F_DRY_RUN) | BIT(F_CELL) | BIT(F_SHARD) | BIT(F_LOCK_TIMEOUT) |
         BIT(F_TASKS),
     1, 1, "CONFIG",
     "usage: tcbench run CONFIG [--root DATASET=DIR]... [--variant NAME] [--dry-run [--tasks K]] [--out DIR]\n"
     "                  [--only METHOD] [--cell IDS] [--shard I/N|auto] [--lock-timeout S]\n"
     "                  [--threads N] [--force] [--quiet] [--verbose] [--report] [--plugin SO]...\n"
     "\n"
     "Runs every (dataset, sequence, method, seed) cell of the config and writes one\n"
     "result file per cell. Finished cells are skipped, so rerunning a killed run\n"
     "resumes it. Each cell is computed under a lock (<cell>.json.lock, heartbeat\n"
     "refreshed while it runs), so any number of 'tcbench run' processes, on any\n"
     "machines sharing the run directory, can work on one config: a locked cell is\n"
     "left to its holder, a stale lock is taken over (and said so).\n"
     "\n"
     "options:\n"
     "  --root D=DIR   the data of the config's dataset D (else $TCBENCH_ROOT_<D>, else the\n"
     "                 config's \"root\"); repeatable\n"
     "  --variant NAME the config's variant (configs/paper/*: cpu, the default, or paper);\n"
     "                 the run goes to <output>/<variant>\n"
     "  --dry-run      list the cells, their state and an estimate of their compute; run nothing.\n"
     "                 Priced by the first calibration that measured the method: <run dir>/\n"
     "                 calibration.json, the user's (tcbench calibrate), the built-in one\n"
     "  --tasks K      with --dry-run: also the wall time of K concurrent one-cell tasks (a\n"
     "                 Slurm array with %K)\n"
     "  --out DIR      run directory (default: the config's \"output\")\n"
     "  --only METHOD  run only the method with this label\n"
     "  --cell IDS     run only these cells (\"3,5-7\"; ids as 'tcbench cells' lists them)\n"
     "  --shard I/N    run only the cells whose id is I modulo N; 'auto' takes I and N from\n"
     "                 a Slurm array task (SLURM_ARRAY_TASK_ID, _MIN/_MAX or _COUNT)\n"
     "  --lock-timeout S  take over a cell lock whose heartbeat is older than S seconds\n"
     "                 (default 600; a lock of a dead process on this host at once)\n"
     "  --threads N    threads per cell (default: SLURM_CPUS_PER_TASK under Slurm, else the\n"
     "                 config's \"threads\", else 2); two processes with --only and\n"
     "                 --threads 1 use two cores more evenly\n"
     "  --force        recompute cells that are already finished\n"
     "  --quiet        no progress output (also when the CI variable is set)\n"
     "  --verbose      also the methods' debug lines (a training's mean loss every 1 000 iterations)\n"
     "  --report       write the report when the run is done\n"
     "  --plugin SO    load out-of-tree methods from a shared object (repeatable)\n"
     "\n"
     "the paper's datasets (configs/paper/*; docs/datasets.md says how to lay them out):\n"
     "  anim    cat_walk: Aujay et al., SCA 2007 (redistributed by the ICCV'21 authors);\n"
     "          horse, camel, elephant gallop and collapse: Sumner & Popovic, SIGGRAPH\n"
     "          2004; one OBJ directory per sequence\n"
     "  ama     Vlasic et al., \"Articulated mesh animation from multi-view silhouettes\",\n"
     "          SIGGRAPH 2008: crane, bouncing, ...; one OBJ directory per sequence\n"
     "  dfaust  Bogo et al., Dynamic FAUST, CVPR 2017: registrations_m.hdf5 and\n"
     "          registrations_f.hdf5 in one directory\n"
     "\n"
     "examples:\n"
     "  tcbench run configs/quick.json --out runs/quick --report\n"
     "  tcbench run configs/paper/table5-nricp.json --root ama=../shared/data/ama --dry-run\n"},
    {"cells", cmd_cells, BIT(F_OUT) | BIT(F_ROOT) | BIT(F_VARIANT) | BIT(F_LOCK_TIMEOUT), 1, 1, "CONFIG",
     "usage: tcbench cells CONFIG [--variant NAME] [--root DATASET=DIR]... [--out DIR] [--lock-timeout S]\n"
     "\n"
     "Lists the config's cells, numbered in one fixed order (datasets, sequences,\n"
     "methods, seeds) that depends only on the config, with each cell's state in the\n"
     "run directory: done, failed, diverged, missing, running (with the holder's\n"
     "progress) or stale (its holder was killed or stopped beating: the next run\n"
     "takes it over). 'tcbench run --cell' and '--shard' take these ids.\n"
     "\n"
     "options:\n"
     "  --variant NAME  the config's variant (default: its first)\n"
     "  --root D=DIR    as for run (the states do not depend on it)\n"
     "  --out DIR       run directory (default: the config's \"output\")\n"
     "  --lock-timeout S  a lock whose heartbeat is older than S s is stale (600)\n"
     "\n"
     "example:\n"
     "  tcbench cells configs/paper/table5-nricp.json\n"},
    {"status", cmd_status, BIT(F_OUT) | BIT(F_ROOT) | BIT(F_VARIANT) | BIT(F_LOCK_TIMEOUT), 1, 1,
     "RUN_DIR or CONFIG",
     "usage: tcbench status RUN_DIR|CONFIG [--variant NAME] [--out DIR] [--lock-timeout S]\n"
     "\n"
     "Where a run stands: the running cells (host, pid, heartbeat age, progress),\n"
     "the stale ones (their holder was killed, or its heartbeat is older than\n"
     "--lock-timeout, 600 s by default: the next run takes them over), the failed\n"
     "and diverged ones with their messages, the count per state, and the ids of\n"
     "the cells a run computes as a Slurm --array list to resubmit. Cells whose array\n"
     "tasks squeue lists as pending or running (jobs of scripts/slurm/submit.sh,\n"
     "whose comment names the run directory) count as queued, not missing. A run\n"
     "directory is read through the config it saved (RUN_DIR/config.json).\n"
     "\n"
     "options:\n"
     "  --variant NAME  with a CONFIG: its variant (default: the first)\n"
     "  --out DIR       with a CONFIG: the run directory (default: its \"output\")\n"
     "  --lock-timeout S  as for run: a lock whose heartbeat is older is stale\n"
     "\n"
     "examples:\n"
     "  tcbench status runs/paper/table6-delta/cpu\n"
     "  sbatch --array=$(tcbench status runs/x | sed -n 's/.*--array=//p') ...\n"},
    {"report", cmd_report, BIT(F_OUT) | BIT(F_QUIET) | BIT(F_REFERENCE) | BIT(F_RESAMPLES), 1, 1, "RUN_DIR",
     "usage: tcbench report RUN_DIR [--reference NAME] [--out DIR] [--resamples N] [--quiet]\n"
     "\n"
     "Writes tables.md, tables.tex, results.csv, by_gap.csv, seeds.csv,\n"
     "comparisons.md, .tex and .csv (each pair of methods per sequence and metric:\n"
     "difference, 95 % bootstrap interval, Holm-adjusted Wilcoxon p), and per sequence the PCK\n"
     "curves, the geodesic PCK curves and m_sL2 by frame distance (log scale) as PNG\n"
     "plots, for a run directory, and prints the Markdown tables (the paper's\n"
     "metrics, then the geodesic error m_geo and AUC_geo: docs/protocol.md) on\n"
     "stdout, nothing else there. A method keeps its colour in every plot.\n"
     "\n"
     "With --reference: the run's tables beside the paper's instead, in the paper's\n"
     "shape: ours, the paper's value and ours/paper per cell, and per metric whether\n"
     "the methods come out in the paper's order (reference_NAME.md, .tex, .csv). The\n"
     "tables are those the run's config names (\"reference\"), else every table\n"
     "naming one of the run's cells; the run's cells no row names (a method the\n"
     "paper did not run) are listed below them.\n"
     "\n"
     "options:\n"
     "  --reference NAME  iccv21 (built in: every table of the ICCV'21 paper and its\n"
     "                    supplement) or a tcbench-reference/1 file\n"
     "  --out DIR         where to write (default: RUN_DIR/report)\n"
     "  --resamples N     bootstrap resamples per comparison (default 10000)\n"
     "  --quiet           do not print the tables\n"
     "\n"
     "A best value is bold only when significantly better than every other method\n"
     "(Holm-adjusted p < 0.05 and the interval excluding 0); otherwise the leaders\n"
     "tied for best are marked (docs/protocol.md, \"Statistics of a comparison\").\n"
     "\n"
     "examples:\n"
     "  tcbench report runs/quick\n"
     "  tcbench report runs/paper/table5-nricp/cpu --reference iccv21\n"},
    {"compare", cmd_compare, BIT(F_SEQUENCE) | BIT(F_DATASET) | BIT(F_RESAMPLES), 3, 3, "RUN_DIR A B",
     "usage: tcbench compare RUN_DIR A B [--sequence S|DATASET/S|MEAN] [--dataset D] [--resamples N]\n"
     "\n"
     "Compares method A with method B (the config's labels) on one sequence: per\n"
     "metric, the means of A and B, A - B with its 95 % interval (seeded\n"
     "hierarchical paired bootstrap: A's seeds, B's seeds, then the split's pairs,\n"
     "the same for both) and the two-sided Wilcoxon signed-rank p of the\n"
     "seed-averaged per-pair differences (raw: one comparison, nothing to adjust\n"
     "for), and whether the difference is significant. With one seed on a side the\n"
     "interval leaves out the training variance; it says so. MEAN: across the\n"
     "dataset's test sequences (the sequences resampled; rough when few).\n"
     "\n"
     "options:\n"
     "  --sequence S   the sequence (default: the only one with cells of both)\n"
     "  --dataset D    its dataset (default: the only one with cells of both)\n"
     "  --resamples N  bootstrap resamples (default 10000)\n"
     "\n"
     "examples:\n"
     "  tcbench compare runs/quick nricp nearest --sequence quadruped_walk\n"
     "  tcbench compare runs/paper/table5-nricp/cpu nricp nearest --sequence MEAN --dataset anim\n"},
    {"methods", cmd_methods, 0, 0, 0, "",
     "usage: tcbench methods [--plugin SO]...\n"
     "\n"
     "Lists the registered methods: name, origin (built-in or plug-in path) and\n"
     "description.\n"
     "\n"
     "options:\n"
     "  --plugin SO  also load the methods of this plug-in (repeatable)\n"
     "\n"
     "example:\n"
     "  tcbench methods --plugin build/examples/libmy_method.so\n"},
    {"datasets", cmd_datasets,
     BIT(F_OUT) | BIT(F_SEED) | BIT(F_FRAMES) | BIT(F_SEQUENCE) | BIT(F_SAMPLES) | BIT(F_PLOT), 1, 2,
     "ACTION (list, synth, align or distortion)",
     "usage: tcbench datasets list\n"
     "       tcbench datasets synth --out DIR [--seed N] [--frames N] [--sequence NAME]\n"
     "       tcbench datasets align DIR --out FILE [--samples N] [--seed N] [--plot PNG]\n"
     "       tcbench datasets distortion NAME|DIR [--seed N] [--frames N]\n"
     "\n"
     "list:  the embedded synthetic sequences.\n"
     "synth: writes synthetic sequences as OBJ files, DIR/<name>/mesh_NNNN.obj\n"
     "       (raw coordinates, before normalization).\n"
     "align: the rotation alignment of an OBJ directory (AMA, paper 4.2): each frame,\n"
     "       centred, turned about y by the multiple of 3 degrees that minimises the\n"
     "       Chamfer distance to the aligned previous frame; writes the angles per\n"
     "       frame as JSON (what a config's \"align_rotation\": true applies).\n"
     "distortion: how far a synthetic sequence (NAME) or an OBJ directory is from\n"
     "       isometric: per frame against frame 0, the mean and max relative change\n"
     "       of edge lengths, the mean relative change of geodesic distances, the\n"
     "       area ratio (raw coordinates).\n"
     "\n"
     "options:\n"
     "  --out DIR|FILE   output directory (synth) or rotations file (align); required\n"
     "  --seed N         generator seed (synth), sample seed (align; a run uses its\n"
     "                   pool_seed); default 0\n"
     "  --frames N       frames per sequence (default: the sequence's own length)\n"
     "  --sequence NAME  only this sequence (default: all)\n"
     "  --samples N      align: points per frame for the Chamfer (default 1000)\n"
     "  --plot PNG       align: also plot the angle per frame\n"
     "\n"
     "examples:\n"
     "  tcbench datasets synth --out data/synth --sequence quadruped_walk\n"
     "  tcbench datasets align ../shared/data/ama/crane --out crane-rotations.json --plot crane-yaw.png\n"
     "  tcbench datasets distortion quadruped_collapse\n"},
    {"check", cmd_check, BIT(F_UPDATE), 2, 2, "RUN_DIR BASELINE",
     "usage: tcbench check RUN_DIR BASELINE [--update]\n"
     "\n"
     "Compares a run with a baseline file and prints the differences. Exit status:\n"
     "0 when every row of the baseline is within tolerance, 1 on drift (including\n"
     "its rows the run lacks), 2 on unreadable or malformed input. Rows the baseline\n"
     "does not name (a method added to the run) are listed, not judged.\n"
     "\n"
     "options:\n"
     "  --update  write BASELINE from the run instead of comparing\n"
     "\n"
     "example:\n"
     "  tcbench check runs/quick tests/baselines/quick.json\n"},
    {"inspect", cmd_inspect, BIT(F_SEED) | BIT(F_SEQUENCE) | BIT(F_OUT) | BIT(F_THREADS) | BIT(F_QUIET),
     3, 3, "RUN_DIR METHOD PAIR",
     "usage: tcbench inspect RUN_DIR METHOD PAIR [--seed S] [--sequence DATASET/SEQUENCE]\n"
     "                       [--out DIR] [--threads N] [--quiet]\n"
     "\n"
     "Recomputes one evaluation pair of a cell exactly as the run did (from the\n"
     "cell's fitted model), checks it against the cell file, and writes it as\n"
     "coloured meshes: source.ply and target.ply (vertices coloured by their place\n"
     "on the body), transfer.ply (each target vertex in the colour of the vertex the\n"
     "method predicted for it), error.ply (per-vertex error), recon_i/recon_j.ply\n"
     "(the method's surface samples, if it reconstructs), vertices.csv (per vertex: the\n"
     "prediction, its error and its geodesic error) and pair.json.\n"
     "\n"
     "PAIR is the pair's index in the split, or 'worst': the cell's pair with the\n"
     "largest m_sL2.\n"
     "\n"
     "options:\n"
     "  --seed S          the cell's seed (default: the run's first)\n"
     "  --sequence D/S    dataset/sequence (default: the run's only one)\n"
     "  --out DIR         where to write (default:\n"
     "                    RUN_DIR/inspect/<dataset>/<sequence>/<method>/seed_<s>/pair_<k>)\n"
     "  --threads N       threads (default: the run's; the same count reproduces the\n"
     "                    cell's numbers bit for bit)\n"
     "  --quiet           no progress output\n"
     "\n"
     "example:\n"
     "  tcbench inspect runs/atlas-cat mca worst --seed 1\n"},
    {"frames", cmd_frames,
     BIT(F_FRAMES) | BIT(F_N_FRAMES) | BIT(F_STYLE) | BIT(F_SEED) | BIT(F_SEQUENCE) | BIT(F_OUT) | BIT(F_THREADS) |
         BIT(F_QUIET),
     2, 2, "RUN_DIR METHOD",
     "usage: tcbench frames RUN_DIR METHOD [--frames F,F,... | --count N] [--style auto|texture|transfer]\n"
     "                      [--seed S] [--sequence DATASET/SEQUENCE] [--out DIR] [--threads N] [--quiet]\n"
     "\n"
     "Draws a few frames of a cell from its fitted model, side by side from one\n"
     "camera in strip.png. A method that reconstructs a parametrised surface (the\n"
     "atlas family: atlasnet, dsr, mca) is drawn as its surface of each frame with\n"
     "one checkerboard in UV space, the same texture in every frame, so a patch that\n"
     "slides over the body shows it at a glance; the surfaces are also written as\n"
     "frame_<f>.obj with checker.mtl and checker.png (MeshLab and Blender open them\n"
     "as they are). A surface without charts (neupig's template moved into each\n"
     "frame) keeps each vertex in the colour of its place in the first frame drawn\n"
     "(frame_<f>.ply), so colours that slide over the body show it. Any other\n"
     "method is drawn as its transfer from the first frame:\n"
     "each frame's GT mesh with every vertex in the colour of the place on the body\n"
     "the transfer sent it to (frame_<f>.ply), so colours out of place are errors.\n"
     "A surface whose patches collapsed (a patch under 5 % of its share of the\n"
     "frame's GT area) is said so above each frame of the strip and in a warning.\n"
     "\n"
     "options:\n"
     "  --frames F,F,...  the frames (at most 16, distinct)\n"
     "  --count N         N frames evenly spaced from the first to the last (default 5)\n"
     "  --style S         texture (needs a method with a surface), transfer, or auto\n"
     "                    (default: texture when the method has one)\n"
     "  --seed S          the cell's seed (default: the run's first)\n"
     "  --sequence D/S    dataset/sequence (default: the run's only one)\n"
     "  --out DIR         where to write (default:\n"
     "                    RUN_DIR/frames/<dataset>/<sequence>/<method>/seed_<s>)\n"
     "  --threads N       threads (default: the run's)\n"
     "  --quiet           no progress output\n"
     "\n"
     "examples:\n"
     "  tcbench frames runs/atlas-cat mca --frames 0,8,16,24\n"
     "  tcbench frames runs/quick nearest --count 4\n"},
    {"score", cmd_score,
     BIT(F_DATASET) | BIT(F_SEQUENCE) | BIT(F_PRED) | BIT(F_NAME) | BIT(F_SEED) | BIT(F_OUT) | BIT(F_FORCE) |
         BIT(F_ROOT) | BIT(F_VARIANT) | BIT(F_THREADS) | BIT(F_ANY_FRAME),
     1, 1, "CONFIG",
     "usage: tcbench score CONFIG --dataset D --sequence S --pred DIR|FILE.npz --name LABEL\n"
     "                    [--seed S] [--out DIR] [--force] [--any-frame] [--root DATASET=DIR]...\n"
     "                    [--variant NAME] [--threads N]\n"
     "\n"
     "Scores correspondences computed anywhere as a cell of the config's run. The\n"
     "predictions hold one NumPy array per evaluation pair of the sequence's common\n"
     "split, named by the pair's index (pair k is the split file's pairs[k] = [i, j]):\n"
     "a directory of .npy files 0.npy, 1.npy, ..., or one .npz whose members are\n"
     "those files (np.savez(FILE, **{str(k): a_k}); stored or deflated). For each of\n"
     "the K vertices of frame i, the array holds either the predicted vertex id of\n"
     "frame j (integers, shape (K,)) or the predicted point on frame j (float32 or\n"
     "float64, shape (K, 3), in the split's normalised frame, projected onto frame\n"
     "j's vertices as a method's transfer is). The pairs are scored by the code that\n"
     "scores a method's cells, and the cell goes to RUN/cells/D/S/LABEL/seed_<S>.json,\n"
     "so 'report' and 'check' show it as a row (CD '-': no reconstructions). A\n"
     "missing or surplus file or member, a wrong shape or dtype, an id out of range,\n"
     "a NaN, points mostly farther than half a box diagonal from frame j's bounding\n"
     "box (another frame: the error says the split's normalisation) are errors\n"
     "naming the file, and nothing is written. docs/formats.md describes the files,\n"
     "with a numpy example.\n"
     "\n"
     "options:\n"
     "  --dataset D     a dataset of the config\n"
     "  --sequence S    one of its sequences\n"
     "  --pred P        the predictions: a directory of <k>.npy, or an .npz\n"
     "  --name LABEL    the row's name; not a label of one of the config's methods\n"
     "  --seed S        the cell's seed (default 0): several prediction sets of one\n"
     "                  method are several seeds of one row\n"
     "  --out DIR       run directory (default: the config's \"output\")\n"
     "  --force         replace the cell when it exists\n"
     "  --any-frame     score points however far they lie from the target frame\n"
     "  --root D=DIR    the data of dataset D, as for run\n"
     "  --variant NAME  the config's variant, as for run\n"
     "  --threads N     threads for the projection and the metrics\n"
     "\n"
     "examples:\n"
     "  tcbench score configs/quick.json --dataset synth --sequence quadruped_trot \\\n"
     "      --pred results.npz --name my_method\n"
     "  tcbench score configs/quick.json --dataset synth --sequence quadruped_walk \\\n"
     "      --pred predictions/ --name my_method\n"},
    {"calibrate", cmd_calibrate,
     BIT(F_QUICK) | BIT(F_THREADS) | BIT(F_ONLY) | BIT(F_PRESET) | BIT(F_BUDGET) | BIT(F_SAMPLES) | BIT(F_OUT), 0, 0, "",
     "usage: tcbench calibrate [--quick] [--threads T,T,...] [--only METHOD] [--preset NAME]\n"
     "                         [--budget SECONDS] [--samples N] [--out FILE]\n"
     "\n"
     "Measures on this machine what 'tcbench run --dry-run' prices cells with: a training\n"
     "step of every trained method at each of its presets, the method's part of an\n"
     "evaluation pair, the reconstruction metrics of a frame (methods with a surface), the\n"
     "units a method names (nricp: a registration, an assignment; neupig: its template),\n"
     "and the harness's scoring of a pair, at each thread count; and writes them with the\n"
     "machine's description (CPU, cores, library versions). Each measurement is a warm-up\n"
     "step, then steps while its share of the budget lasts (at least one: the largest\n"
     "presets may overrun a small budget, which the last line says); a unit likewise.\n"
     "\n"
     "The dry run reads, first match wins: <run dir>/calibration.json (a calibration made\n"
     "on the nodes that run it: --out RUN_DIR/calibration.json in a job there), the user's\n"
     "file (the default --out), the built-in one (calibration/default.json, which names\n"
     "the machine it came from). Calibrating into an existing file of this machine keeps\n"
     "its costs that were not measured again.\n"
     "\n"
     "options:\n"
     "  --quick        a coarse pass (default budget 60 s): about a minute on 2 idle cores,\n"
     "                 most of it the paper presets' warm-up and one step\n"
     "  --threads T,.. the thread counts to measure (default 1, 2 and every core)\n"
     "  --only METHOD  measure this method only\n"
     "  --preset NAME  measure this preset only\n"
     "  --budget S     seconds for the whole measurement (default 600; --quick 60)\n"
     "  --samples N    surface samples per mesh of the reconstruction metrics measured\n"
     "                 (default 100000, as evaluation.surface_samples; the dry run scales)\n"
     "  --out FILE     where to write (default $XDG_CONFIG_HOME/tcbench/calibration.json,\n"
     "                 else ~/.config/tcbench/calibration.json)\n"
     "\n"
     "examples:\n"
     "  tcbench calibrate --quick\n"
     "  tcbench calibrate --only dsr --preset paper --threads 1,2,4,8\n"},
    {"version", cmd_version, 0, 0, 0, "",
     "usage: tcbench version\n"
     "\n"
     "Prints the tcbench version and the git revision of its source tree.\n"
     "\n"
     "example:\n"
     "  tcbench version\n"},
    {"help", cmd_help, 0, 0, 1, "",
     "usage: tcbench help [COMMAND]\n"
     "\n"
     "Prints the list of commands, or the help of one command.\n"
     "\n"
     "example:\n"
     "  tcbench help run\n"},
};
#define N_COMMANDS ((int)(sizeof commands / sizeof commands[0]))

static const char general_help[] =
    "usage: tcbench [--plugin SO]... COMMAND [ARGS]\n"
    "\n"
    "A benchmark for temporally-coherent surface reconstruction and dense\n"
    "correspondence on deforming 3-D shapes.\n"
    "\n"
    "commands:\n"
    "  run       run the grid of a config (resumable)\n"
    "  cells     the numbered cells of a config and their state\n"
    "  status    where a run stands; the missing cells as a Slurm --array list\n"
    "  report    tables and plots from a run directory\n"
    "  compare   is the difference between two methods real? interval and p per metric\n"
    "  methods   list the registered methods\n"
    "  datasets  list or export the synthetic sequences, align an OBJ sequence's rotations\n"
    "  check     compare a run with a baseline (CI regression check)\n"
    "  inspect   one evaluation pair as coloured meshes, checked against the run\n"
    "  frames    a few frames of a cell as a picture: checkerboard-textured surfaces or transfers\n"
    "  score     score correspondences computed elsewhere (.npy files) as a cell of a run\n"
    "  calibrate measure step and evaluation costs on this machine for the dry run's estimates\n"
    "  version   print the version\n"
    "  help      help on a command\n"
    "\n"
    "'tcbench COMMAND --help' describes a command.\n"
    "example:\n"
    "  tcbench run configs/quick.json && tcbench report runs/quick\n";

static const command *find_command(const char *name)
{
    for (int k = 0; k < N_COMMANDS; k++)
        if (strcmp(commands[k].name, name) == 0) return &commands[k];
    return NULL;
}

static int cmd_help(const cli *c)
{
    const command *cmd = c->n_args ? find_command(c->arg[0]) : NULL;
    if (c->n_args && !cmd) return usage_error(NULL, "unknown command '%s'", c->arg[0]);
    fputs(cmd ? cmd->help : general_help, stdout);
    return 0;
}

/* ---- argument parsing ----------------------------------------------- */

/* --root DATASET=DIR, one per dataset. */
static int add_root(const char *where, const char *value, cli *c)
{
    const char *sep = strchr(value, '=');
    size_t n = sep ? (size_t)(sep - value) : 0;
    if (!sep || !n || !sep[1] || n >= sizeof c->root_names[0])
        return usage_error(where, "--root: expected DATASET=DIR, got '%s'", value);
    if (c->n_roots == MAX_ROOTS) return usage_error(where, "too many --root options");
    memcpy(c->root_names[c->n_roots], value, n);
    c->root_names[c->n_roots][n] = '\0';
    for (int k = 0; k < c->n_roots; k++)
        if (!strcmp(c->root_names[k], c->root_names[c->n_roots]))
            return usage_error(where, "--root: dataset '%s' given twice", c->root_names[k]);
    c->roots[c->n_roots] = (tcb_root_override){c->root_names[c->n_roots], sep + 1};
    c->n_roots++;
    return 0;
}

/* Parses argv[*i] (a flag) into c; advances *i past a separate value.
 * `cmd` is NULL before the command name, where only global flags apply. */
static int parse_flag(const command *cmd, int argc, char **argv, int *i, cli *c)
{
    char name[64];
    const char *arg = argv[*i], *eq = strchr(arg, '=');
    size_t len = eq ? (size_t)(eq - arg) : strlen(arg);
    snprintf(name, sizeof name, "%.*s", (int)len, arg);
    if (strcmp(name, "-h") == 0) snprintf(name, sizeof name, "--help");
    int f = 0;
    while (f < F_COUNT && strcmp(flags[f].name, name) != 0) f++;
    unsigned long long accepted = BIT(F_PLUGIN) | BIT(F_HELP) | (cmd ? cmd->accepts : 0);
    const char *where = cmd ? cmd->name : NULL;
    if (f == F_COUNT || !(accepted & BIT(f))) return usage_error(where, "unknown option '%s'", name);
    const char *value = NULL;
    if (flags[f].takes_value) {
        value = eq ? eq + 1 : *i + 1 < argc ? argv[++*i] : NULL;
        if (!value) return usage_error(where, "option '%s' needs a value", name);
    } else if (eq) {
        return usage_error(where, "option '%s' takes no value", name);
    }
    /* A second value would silently replace the first: which one was meant? */
    if (value && c->set[f] && f != F_PLUGIN && f != F_ROOT)
        return usage_error(where, "option '%s' given twice ('%s', then '%s')", name, c->value[f], value);
    int rc = value ? parse_int_flag(where, f, value, &c->num[f]) : 0;
    if (rc) return rc;
    if (f == F_PLUGIN) {
        if (c->n_plugins == MAX_PLUGINS) return usage_error(where, "too many %s options", name);
        c->plugins[c->n_plugins++] = value;
    }
    if (f == F_ROOT && (rc = add_root(where, value, c))) return rc;
    c->set[f] = 1;
    c->value[f] = value;
    return 0;
}

static int parse_command_args(const command *cmd, int argc, char **argv, int i, cli *c)
{
    int only_args = 0;
    for (; i < argc; i++) {
        const char *a = argv[i];
        if (!only_args && strcmp(a, "--") == 0) {
            only_args = 1;
        } else if (!only_args && a[0] == '-' && a[1]) {
            int rc = parse_flag(cmd, argc, argv, &i, c);
            if (rc) return rc;
        } else if (c->n_args == cmd->max_args) {
            return usage_error(cmd->name, "unexpected argument '%s'", a);
        } else {
            c->arg[c->n_args++] = a;
        }
    }
    if (!c->set[F_HELP] && c->n_args < cmd->min_args)
        return usage_error(cmd->name, "missing %s", cmd->arg_names);
    return 0;
}

static int load_plugins(const cli *c)
{
    for (int k = 0; k < c->n_plugins; k++) {
        tcb_error err = {0};
        if (tcb_registry_load_plugin(c->plugins[k], &err)) return fail(&err);
    }
    return 0;
}

int main(int argc, char **argv)
{
    cli c = {0};
    int i = 1, rc;
    /* Tables on stdout, status lines on stderr: line by line, each stream in
     * the order written, so that `tcbench report > file 2>&1` never finds a
     * status line inside a table (a fully buffered stdout reached the file
     * in 4 KiB blocks, after the stderr lines written meanwhile). */
    setvbuf(stdout, NULL, _IOLBF, 0);
    /* Global flags (--plugin, --help) may precede the command. */
    for (; i < argc && argv[i][0] == '-'; i++)
        if ((rc = parse_flag(NULL, argc, argv, &i, &c))) return rc;
    if (i == argc) {
        fputs(general_help, c.set[F_HELP] ? stdout : stderr);
        return c.set[F_HELP] ? 0 : 2;
    }
    const command *cmd = find_command(argv[i]);
    if (!cmd) return usage_error(NULL, "unknown command '%s'", argv[i]);
    if ((rc = parse_command_args(cmd, argc, argv, i + 1, &c))) return rc;
    if (c.set[F_HELP]) {
        fputs(cmd->help, stdout);
        return 0;
    }
    if ((rc = load_plugins(&c))) return rc;
    return cmd->fn(&c);
}
