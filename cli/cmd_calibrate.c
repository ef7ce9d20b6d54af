/* `tcbench calibrate`: this machine's costs for the dry run's estimates. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli/cli.h"
#include "costs/calibrate.h"
#include "costs/calibration.h"
#include "tcb/config.h"
#include "tcb/fsutil.h"
#include "tcb/metrics.h"
#include "tcb/runner.h"
#include "tcb/sysinfo.h"

/* calibrate --threads: "1,2,16", kept increasing without repeats. */
static int thread_list(const char *text, int *threads, int max, int *n)
{
    *n = 0;
    for (const char *p = text; *p;) {
        char *end;
        errno = 0;
        long t = strtol(p, &end, 10);
        if (end == p || errno || t < 1 || t > 1024 || (*end && *end != ',') || (*end == ',' && !end[1]))
            return cli_usage_error("calibrate", "--threads: expected thread counts from 1 to 1024 separated by commas, "
                               "got '%s'", text);
        int at = 0;
        while (at < *n && threads[at] < t) at++;
        if (at == *n || threads[at] != t) {
            if (*n == max) return cli_usage_error("calibrate", "--threads: more than %d thread counts", max);
            memmove(threads + at + 1, threads + at, (size_t)(*n - at) * sizeof *threads);
            threads[at] = (int)t, (*n)++;
        }
        p = *end ? end + 1 : end;
    }
    return 0;
}

/* The units of cfg's methods and the scoring of a pair on each of its
 * sequences (loaded as `run` loads them), the budget shared between the
 * sequences; a sequence of an optional dataset that is absent is skipped,
 * as a run skips it. */
static int calibrate_on_config(const tcb_config *cfg, tcb_calibrate_opts *o, tcb_error *err)
{
    const char **names = calloc((size_t)cfg->n_methods + 1, sizeof *names);
    if (!names) return tcb_fail(err, TCB_ERR_NOMEM, "out of memory");
    for (int k = 0; k < cfg->n_methods; k++) names[k] = cfg->methods[k].method;
    int n_seqs = 0, rc = TCB_OK;
    for (int d = 0; d < cfg->n_datasets; d++) n_seqs += cfg->datasets[d].n_sequences;
    o->methods = names, o->n_methods = cfg->n_methods, o->budget_s /= n_seqs > 0 ? n_seqs : 1;
    rc = tcb_calibrate_check(o, err);
    for (int d = 0; !rc && d < cfg->n_datasets; d++) {
        const tcb_dataset_spec *ds = &cfg->datasets[d];
        for (int k = 0; !rc && k < ds->n_sequences; k++) {
            char name[TCB_COST_SEQUENCE_MAX];
            tcb_sequence seq;
            snprintf(name, sizeof name, "%s/%s", ds->name, ds->sequences[k].name);
            rc = tcb_run_load_sequence(cfg, ds->name, ds->sequences[k].name, &seq, err);
            if (rc && ds->optional) {
                printf("%s: skipped (optional): %s\n", name, err->msg);
                rc = TCB_OK;
                continue;
            }
            if (rc) break;
            o->sequence = &seq, o->sequence_name = name;
            rc = tcb_calibrate(o, stdout, err);
            if (rc) tcb_error_prefix(err, "%s: ", name);
            tcb_sequence_free(&seq);
        }
    }
    free(names);
    if (rc) tcb_error_prefix(err, "%s: ", cfg->path);
    return rc;
}

static int cmd_calibrate(const cli_args *c)
{
    enum { MAX_COUNTS = 16 };
    char cores[16], user[TCB_PATH_MAX];
    snprintf(cores, sizeof cores, "1,2,%d", tcb_cpu_count());
    int threads[MAX_COUNTS], n = 0;
    int rc = thread_list(c->set[F_THREADS] ? c->value[F_THREADS] : cores, threads, MAX_COUNTS, &n);
    if (rc) return rc;
    tcb_calibration_user_path(user, sizeof user);
    const char *out = c->value[F_OUT] ? c->value[F_OUT] : user;
    if (!out[0]) return cli_usage_error("calibrate", "neither HOME nor XDG_CONFIG_HOME is set: give --out FILE");
    tcb_calibrate_opts o = {.threads = threads, .n_threads = n, .method = c->value[F_ONLY],
                            .preset = c->value[F_PRESET],
                            .budget_s = (double)cli_flag_int(c, F_BUDGET, c->set[F_QUICK] ? 60 : 600),
                            .quick = c->set[F_QUICK],
                            .surface_samples = (int)cli_flag_int(c, F_SAMPLES, TCB_DEFAULT_SURFACE_SAMPLES),
                            .out_path = out};
    tcb_error err = {0};
    if (!c->n_args) return tcb_calibrate(&o, stdout, &err) ? cli_fail(&err) : 0;
    tcb_config cfg;
    if (tcb_config_load(c->arg[0], &cfg, &err)) return cli_fail(&err);
    rc = calibrate_on_config(&cfg, &o, &err);
    tcb_config_free(&cfg);
    return rc ? cli_fail(&err) : 0;
}

const cli_command cli_calibrate = {
    .name = "calibrate", .fn = cmd_calibrate, .min_args = 0, .max_args = 1, .arg_names = "[CONFIG]",
    .accepts = BIT(F_QUICK) | BIT(F_THREADS) | BIT(F_ONLY) | BIT(F_PRESET) | BIT(F_BUDGET) | BIT(F_SAMPLES) |
        BIT(F_OUT),
    .summary = "measure step and evaluation costs on this machine for the dry run's estimates",
    .usage =
        "usage: tcbench calibrate [--quick] [--threads T,T,...] [--only METHOD] [--preset NAME]\n"
        "                         [--budget SECONDS] [--samples N] [--out FILE] [CONFIG]\n"
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
        "With a CONFIG, only the units of its methods and the scoring of a pair, measured on\n"
        "each of its sequences (the budget shared between them) and written as costs of that\n"
        "sequence: the dry run prices that sequence's cells with them over the calibration\n"
        "sequence's, which it scales by the vertex count only (on crane a registration costs\n"
        "twice the calibration sequence's per point, a pair's scoring 2.3 to 2.8 times its\n"
        "scaled price). Training steps do not depend on the sequence beyond its counts and\n"
        "are not measured again.\n"
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
        "  tcbench calibrate --only dsr --preset paper --threads 1,2,4,8\n"
        "  tcbench calibrate --only nricp --threads 1 --budget 120 configs/crane.json\n"
};
