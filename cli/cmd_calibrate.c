/* `tcbench calibrate`: this machine's costs for the dry run's estimates. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli/cli.h"
#include "costs/calibrate.h"
#include "costs/calibration.h"
#include "tcb/fsutil.h"
#include "tcb/metrics.h"
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
    tcb_calibrate_opts o = {threads, n, c->value[F_ONLY], c->value[F_PRESET],
                            (double)cli_flag_int(c, F_BUDGET, c->set[F_QUICK] ? 60 : 600), c->set[F_QUICK],
                            (int)cli_flag_int(c, F_SAMPLES, TCB_DEFAULT_SURFACE_SAMPLES), out};
    tcb_error err = {0};
    return tcb_calibrate(&o, stdout, &err) ? cli_fail(&err) : 0;
}

const cli_command cli_calibrate = {
    .name = "calibrate", .fn = cmd_calibrate, .min_args = 0, .max_args = 0, .arg_names = "",
    .accepts = BIT(F_QUICK) | BIT(F_THREADS) | BIT(F_ONLY) | BIT(F_PRESET) | BIT(F_BUDGET) | BIT(F_SAMPLES) |
        BIT(F_OUT),
    .summary = "measure step and evaluation costs on this machine for the dry run's estimates",
    .usage =
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
        "  tcbench calibrate --only dsr --preset paper --threads 1,2,4,8\n"
};
