/* `tcbench run`, `cells` and `status`: the grid of a config run, listed
 * with each cell's state, and where a run stands. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli/cli.h"
#include "cli/stop_signals.h"
#include "tcb/fsutil.h"
#include "tcb/progress.h"
#include "tcb/report.h"
#include "tcb/runner.h"

/* --cell and --shard as a mask over the config's cell ids; *mask NULL:
 * every cell. */
static int cell_mask(const cli_args *c, const tcb_config *cfg, unsigned char **mask)
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
    return cli_fail(&err);
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
static int finish_run(const cli_args *c, const char *run_dir, const tcb_run_stats *st)
{
    tcb_error err = {0};
    print_counts(st);
    fprintf(stderr, "results: %s\n", run_dir);
    int rc = st->cells_failed ? 1 : 0;
    if (!c->set[F_REPORT]) {
        fprintf(stderr, "make the report: tcbench report %s\n", run_dir);
        return rc;
    }
    if (tcb_report_write(run_dir, NULL, c->set[F_QUIET] ? NULL : stdout, &err)) return cli_fail(&err);
    fprintf(stderr, "report: %s/report/\n", run_dir);
    return rc;
}

static int cmd_run(const cli_args *c)
{
    tcb_error err = {0};
    tcb_config cfg;
    unsigned char *mask;
    if (c->set[F_TASKS] && !c->set[F_DRY_RUN]) return cli_usage_error("run", "--tasks applies to --dry-run only");
    int rc = cli_load_config(c, &cfg);
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
                         .cells = mask, .lock_timeout_s = (double)cli_flag_int(c, F_LOCK_TIMEOUT, 0),
                         .tasks = (int)cli_flag_int(c, F_TASKS, 0),
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
    else if (rc) rc = cli_fail(&err);
    tcb_run_stats_free(&st);
    return rc;
}

/* `tcbench status RUN_DIR|CONFIG`: a run directory is read through the
 * config it saved (<run>/config.json, already resolved). */
static int cmd_status(const cli_args *c)
{
    tcb_error err = {0};
    tcb_config cfg;
    char saved[TCB_PATH_MAX];
    cli_args resolved = *c;
    if (tcb_is_dir(c->arg[0])) {
        if (tcb_path_join(saved, sizeof saved, &err, "%s/config.json", c->arg[0])) return cli_fail(&err);
        resolved.arg[0] = saved;
        if (!resolved.value[F_OUT]) resolved.value[F_OUT] = c->arg[0];
    }
    int rc = cli_load_config(&resolved, &cfg);
    if (rc) return rc;
    tcb_term_progress tp; /* warnings only (squeue's failure) */
    tcb_term_progress_init(&tp, stderr, 1);
    tcb_run_opts opts = {.output = resolved.value[F_OUT], .reporter = tcb_term_progress_reporter(&tp),
                         .lock_timeout_s = (double)cli_flag_int(&resolved, F_LOCK_TIMEOUT, 0)};
    rc = tcb_run_status(&cfg, &opts, stdout, &err);
    tcb_config_free(&cfg);
    return rc ? cli_fail(&err) : 0;
}

static int cmd_cells(const cli_args *c)
{
    tcb_error err = {0};
    tcb_config cfg;
    int rc = cli_load_config(c, &cfg);
    if (rc) return rc;
    tcb_run_opts opts = {.output = c->value[F_OUT], .lock_timeout_s = (double)cli_flag_int(c, F_LOCK_TIMEOUT, 0)};
    rc = tcb_run_list_cells(&cfg, &opts, stdout, &err);
    tcb_config_free(&cfg);
    return rc ? cli_fail(&err) : 0;
}

const cli_command cli_run = {
    .name = "run", .fn = cmd_run, .min_args = 1, .max_args = 1, .arg_names = "CONFIG",
    .accepts = BIT(F_OUT) | BIT(F_ONLY) | BIT(F_FORCE) | BIT(F_QUIET) | BIT(F_REPORT) | BIT(F_THREADS) |
        BIT(F_VERBOSE) | BIT(F_ROOT) | BIT(F_VARIANT) | BIT(F_DRY_RUN) | BIT(F_CELL) | BIT(F_SHARD) |
        BIT(F_LOCK_TIMEOUT) | BIT(F_TASKS),
    .summary = "run the grid of a config (resumable)",
    .usage =
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
        "  tcbench run configs/paper/table5-nricp.json --root ama=../shared/data/ama --dry-run\n"
};

const cli_command cli_cells = {
    .name = "cells", .fn = cmd_cells, .min_args = 1, .max_args = 1, .arg_names = "CONFIG",
    .accepts = BIT(F_OUT) | BIT(F_ROOT) | BIT(F_VARIANT) | BIT(F_LOCK_TIMEOUT),
    .summary = "the numbered cells of a config and their state",
    .usage =
        "usage: tcbench cells CONFIG [--variant NAME] [--root DATASET=DIR]... [--out DIR] [--lock-timeout S]\n"
        "\n"
        "Lists the config's cells, numbered in one fixed order (datasets, sequences,\n"
        "methods, seeds) that depends only on the config, with each cell's state in the\n"
        "run directory: done, failed, diverged, missing, running (with the holder's\n"
        "progress) or stale (its holder was killed or stopped beating: the next run\n"
        "takes it over). 'tcbench run --cell' and '--shard' take these ids. A method\n"
        "whose params or plug-in build differ from those the run directory recorded\n"
        "under its label has '(other settings)' after the state: a run leaves its\n"
        "cells alone ('tcbench run CONFIG --force --only LABEL' recomputes them).\n"
        "\n"
        "options:\n"
        "  --variant NAME  the config's variant (default: its first)\n"
        "  --root D=DIR    as for run (the states do not depend on it)\n"
        "  --out DIR       run directory (default: the config's \"output\")\n"
        "  --lock-timeout S  a lock whose heartbeat is older than S s is stale (600)\n"
        "\n"
        "example:\n"
        "  tcbench cells configs/paper/table5-nricp.json\n"
};

const cli_command cli_status = {
    .name = "status", .fn = cmd_status, .min_args = 1, .max_args = 1, .arg_names = "RUN_DIR or CONFIG",
    .accepts = BIT(F_OUT) | BIT(F_ROOT) | BIT(F_VARIANT) | BIT(F_LOCK_TIMEOUT),
    .summary = "where a run stands; the missing cells as a Slurm --array list",
    .usage =
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
        "  sbatch --array=$(tcbench status runs/x | sed -n 's/.*--array=//p') ...\n"
};
