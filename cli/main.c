/* tcbench — the command-line interface.
 *
 * A thin layer over libtcbench: parse arguments, call the library, print.
 * Data (tables, lists) goes to stdout, status lines and errors to stderr.
 * Every error is one line "tcbench: <message>"; bad usage, bad input and
 * unreadable paths exit 2, other failures 1.
 *
 * This file is the table of commands and the dispatch (git's git.c is the
 * model): each command's code and its usage text live in cli/cmd_*.c,
 * the flag parsing in cli/args.c. A new command is a file defining its
 * cli_command and one line below. */
#include <stdio.h>
#include <string.h>

#include "cli/cli.h"
#include "tcb/registry.h"

static const cli_command cli_help;

/* In the order the general help lists them. */
static const cli_command *const commands[] = {
    &cli_run,       /* cli/cmd_run.c */
    &cli_cells,     /* cli/cmd_run.c */
    &cli_status,    /* cli/cmd_run.c */
    &cli_report,    /* cli/cmd_report.c */
    &cli_compare,   /* cli/cmd_report.c */
    &cli_methods,   /* cli/cmd_methods.c */
    &cli_datasets,  /* cli/cmd_datasets.c */
    &cli_check,     /* cli/cmd_report.c */
    &cli_inspect,   /* cli/cmd_inspect.c */
    &cli_frames,    /* cli/cmd_inspect.c */
    &cli_score,     /* cli/cmd_score.c */
    &cli_calibrate, /* cli/cmd_calibrate.c */
    &cli_version,   /* cli/cmd_version.c */
    &cli_help,      /* below */
};
#define N_COMMANDS ((int)(sizeof commands / sizeof commands[0]))

static const cli_command *find_command(const char *name)
{
    for (int k = 0; k < N_COMMANDS; k++)
        if (strcmp(commands[k]->name, name) == 0) return commands[k];
    return NULL;
}

/* `tcbench --help`: the commands with their summaries. */
static void general_help(FILE *out)
{
    fputs("usage: tcbench [--plugin SO]... COMMAND [ARGS]\n"
          "\n"
          "A benchmark for temporally-coherent surface reconstruction and dense\n"
          "correspondence on deforming 3-D shapes.\n"
          "\n"
          "commands:\n",
          out);
    for (int k = 0; k < N_COMMANDS; k++) fprintf(out, "  %-9s %s\n", commands[k]->name, commands[k]->summary);
    fputs("\n"
          "'tcbench COMMAND --help' describes a command.\n"
          "example:\n"
          "  tcbench run configs/quick.json && tcbench report runs/quick\n",
          out);
}

static int cmd_help(const cli_args *c)
{
    const cli_command *cmd = c->n_args ? find_command(c->arg[0]) : NULL;
    if (c->n_args && !cmd) return cli_usage_error(NULL, "unknown command '%s'", c->arg[0]);
    if (cmd) fputs(cmd->usage, stdout);
    else general_help(stdout);
    return 0;
}

static const cli_command cli_help = {
    .name = "help", .fn = cmd_help, .min_args = 0, .max_args = 1, .arg_names = "",
    .summary = "help on a command",
    .usage =
        "usage: tcbench help [COMMAND]\n"
        "\n"
        "Prints the list of commands, or the help of one command.\n"
        "\n"
        "example:\n"
        "  tcbench help run\n",
};

static int load_plugins(const cli_args *c)
{
    for (int k = 0; k < c->n_plugins; k++) {
        tcb_error err = {0};
        if (tcb_registry_load_plugin(c->plugins[k], &err)) return cli_fail(&err);
    }
    return 0;
}

int main(int argc, char **argv)
{
    cli_args c = {0};
    int i = 1, rc;
    /* Tables on stdout, status lines on stderr: line by line, each stream in
     * the order written, so that `tcbench report > file 2>&1` never finds a
     * status line inside a table (a fully buffered stdout reached the file
     * in 4 KiB blocks, after the stderr lines written meanwhile). */
    setvbuf(stdout, NULL, _IOLBF, 0);
    /* Global flags (--plugin, --help) may precede the command. */
    for (; i < argc && argv[i][0] == '-'; i++)
        if ((rc = cli_parse_flag(NULL, argc, argv, &i, &c))) return rc;
    if (i == argc) {
        general_help(c.set[F_HELP] ? stdout : stderr);
        return c.set[F_HELP] ? 0 : 2;
    }
    const cli_command *cmd = find_command(argv[i]);
    if (!cmd) return cli_usage_error(NULL, "unknown command '%s'", argv[i]);
    if ((rc = cli_parse_command_args(cmd, argc, argv, i + 1, &c))) return rc;
    if (c.set[F_HELP]) {
        fputs(cmd->usage, stdout);
        return 0;
    }
    if ((rc = load_plugins(&c))) return rc;
    return cmd->fn(&c);
}
