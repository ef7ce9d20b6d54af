/* `tcbench report`, `compare` and `check`: a run directory's tables and
 * plots, whether two methods differ, and the regression check against a
 * baseline. */
#include <stdio.h>

#include "cli/cli.h"
#include "tcb/compare.h"
#include "tcb/report.h"

static int cmd_report(const cli_args *c)
{
    tcb_error err = {0};
    const char *out = c->value[F_OUT];
    if (c->value[F_REFERENCE]) {
        FILE *echo = c->set[F_QUIET] ? NULL : stdout;
        if (tcb_report_reference_resampled(c->arg[0], c->value[F_REFERENCE], out, (int)cli_flag_int(c, F_RESAMPLES, 0),
                                           echo, &err))
            return cli_fail(&err);
        fprintf(stderr, "report: %s/reference_*.{md,tex,csv}\n", out ? out : c->arg[0]);
        return 0;
    }
    if (tcb_report_write_resampled(c->arg[0], out, (int)cli_flag_int(c, F_RESAMPLES, 0), c->set[F_QUIET] ? NULL : stdout,
                                   &err))
        return cli_fail(&err);
    if (out) fprintf(stderr, "report: %s/\n", out);
    else fprintf(stderr, "report: %s/report/\n", c->arg[0]);
    return 0;
}

static int cmd_compare(const cli_args *c)
{
    tcb_error err = {0};
    if (tcb_compare_run(c->arg[0], c->value[F_DATASET], c->value[F_SEQUENCE], c->arg[1], c->arg[2],
                        (int)cli_flag_int(c, F_RESAMPLES, 0), stdout, &err))
        return cli_fail(&err);
    return 0;
}

static int cmd_check(const cli_args *c)
{
    tcb_error err = {0};
    const char *run = c->arg[0], *baseline = c->arg[1];
    if (c->set[F_UPDATE]) {
        if (tcb_baseline_write(run, baseline, &err)) return cli_fail(&err);
        fprintf(stderr, "baseline written: %s\n", baseline);
        return 0;
    }
    int n_drift = 0;
    if (tcb_check(run, baseline, stdout, &n_drift, &err)) return cli_fail(&err);
    if (!n_drift) return 0;
    fprintf(stderr, "tcbench: %d row%s of %s drifted from %s\n", n_drift, n_drift == 1 ? "" : "s",
            run, baseline);
    return 1;
}

const cli_command cli_report = {
    .name = "report", .fn = cmd_report, .min_args = 1, .max_args = 1, .arg_names = "RUN_DIR",
    .accepts = BIT(F_OUT) | BIT(F_QUIET) | BIT(F_REFERENCE) | BIT(F_RESAMPLES),
    .summary = "tables and plots from a run directory",
    .usage =
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
        "  tcbench report runs/paper/table5-nricp/cpu --reference iccv21\n"
};

const cli_command cli_compare = {
    .name = "compare", .fn = cmd_compare, .min_args = 3, .max_args = 3, .arg_names = "RUN_DIR A B",
    .accepts = BIT(F_SEQUENCE) | BIT(F_DATASET) | BIT(F_RESAMPLES),
    .summary = "is the difference between two methods real? interval and p per metric",
    .usage =
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
        "  tcbench compare runs/paper/table5-nricp/cpu nricp nearest --sequence MEAN --dataset anim\n"
};

const cli_command cli_check = {
    .name = "check", .fn = cmd_check, .min_args = 2, .max_args = 2, .arg_names = "RUN_DIR BASELINE",
    .accepts = BIT(F_UPDATE),
    .summary = "compare a run with a baseline (CI regression check)",
    .usage =
        "usage: tcbench check RUN_DIR BASELINE [--update]\n"
        "\n"
        "Compares a run with a baseline file and prints the differences. Exit status:\n"
        "0 when every row of the baseline is within tolerance, 1 on drift (including\n"
        "its rows the run lacks), 2 on unreadable or malformed input. Rows the baseline\n"
        "does not name (a method added to the run) are listed, not judged.\n"
        "\n"
        "options:\n"
        "  --update  write BASELINE from the run instead of comparing; the tolerances\n"
        "            of the BASELINE it replaces (the file's and its rows' own) are kept\n"
        "\n"
        "example:\n"
        "  tcbench check runs/quick tests/baselines/quick.json\n"
};
