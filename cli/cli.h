/* The command line's own header (cli/, linked into the tcbench executable
 * only): the parsed arguments every command receives, the command
 * descriptor each cli/cmd_*.c file defines, and the helpers they share
 * (cli/args.c). main.c's table lists the commands, one line each.
 *
 * Errors are one line "tcbench: <message>" on stderr: bad usage, bad input
 * and unreadable paths exit 2, other failures 1. */
#ifndef TCB_CLI_H
#define TCB_CLI_H

#include "tcb/config.h"
#include "tcb/error.h"

/* Every flag any command takes; a command accepts those in its `accepts`. */
enum {
    F_OUT, F_ONLY, F_FORCE, F_QUIET, F_REPORT, F_SEED, F_FRAMES, F_SEQUENCE, F_UPDATE,
    F_PLUGIN, F_THREADS, F_VERBOSE, F_SAMPLES, F_PLOT, F_ROOT, F_VARIANT, F_DRY_RUN, F_REFERENCE, F_CELL,
    F_SHARD, F_LOCK_TIMEOUT, F_DATASET, F_PRED, F_NAME, F_HELP,
    F_N_FRAMES, F_STYLE, F_ANY_FRAME, F_RESAMPLES, F_QUICK, F_PRESET, F_BUDGET, F_TASKS, F_COUNT
};
#define BIT(f) (1ull << (f))

/* The flag's spelling and whether a value follows it. */
typedef struct cli_flag {
    const char *name;
    int takes_value;
} cli_flag;
extern const cli_flag cli_flags[F_COUNT];

#define CLI_MAX_PLUGINS 64
#define CLI_MAX_ROOTS 16
#define CLI_MAX_ARGS 4

/* One command line, parsed. */
typedef struct cli_args {
    const char *arg[CLI_MAX_ARGS];   /* positional arguments */
    int n_args;
    const char *value[F_COUNT];      /* the value of each flag taking one */
    long long num[F_COUNT];          /* ... as an integer, for the integer flags (cli/args.c) */
    int set[F_COUNT];                /* flag given */
    const char *plugins[CLI_MAX_PLUGINS];
    int n_plugins;
    tcb_root_override roots[CLI_MAX_ROOTS]; /* --root NAME=DIR; dataset points into root_names */
    char root_names[CLI_MAX_ROOTS][64];
    int n_roots;
} cli_args;

/* A command: its name, code, the flags it accepts beside the global ones
 * (--plugin, --help), its positional arguments, its line in the general
 * help and its --help text. Each is defined beside its code in
 * cli/cmd_<name>.c. */
typedef struct cli_command {
    const char *name;
    int (*fn)(const cli_args *c);
    int min_args, max_args;
    const char *arg_names;      /* for "missing ..." messages */
    unsigned long long accepts; /* BIT(F_...) */
    const char *summary;
    const char *usage;
} cli_command;

extern const cli_command cli_run, cli_cells, cli_status;        /* cli/cmd_run.c */
extern const cli_command cli_report, cli_compare, cli_check;    /* cli/cmd_report.c */
extern const cli_command cli_methods;                            /* cli/cmd_methods.c */
extern const cli_command cli_datasets;                           /* cli/cmd_datasets.c */
extern const cli_command cli_inspect, cli_frames;                /* cli/cmd_inspect.c */
extern const cli_command cli_score;                              /* cli/cmd_score.c */
extern const cli_command cli_calibrate;                          /* cli/cmd_calibrate.c */
extern const cli_command cli_version;                            /* cli/cmd_version.c */

/* Prints err's message as the one error line; the exit status for it. */
int cli_fail(const tcb_error *err);
/* Bad usage: names the command (NULL: none yet) and the offending word,
 * points to its --help; returns 2. */
int cli_usage_error(const char *cmd, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

/* argv[*i], a flag, into c; advances *i past a separate value. `cmd` is
 * NULL before the command name, where only the global flags apply. */
int cli_parse_flag(const cli_command *cmd, int argc, char **argv, int *i, cli_args *c);
/* argv[i..] as cmd's flags and positional arguments. */
int cli_parse_command_args(const cli_command *cmd, int argc, char **argv, int i, cli_args *c);

/* Flag f's integer (checked when the line was parsed), or `def` when not
 * given. */
long long cli_flag_int(const cli_args *c, int f, long long def);

/* The config arg[0] as the command line shapes it: variant, roots, threads
 * (the flag, else Slurm's SLURM_CPUS_PER_TASK, else the config's). */
int cli_load_config(const cli_args *c, tcb_config *cfg);

#endif
