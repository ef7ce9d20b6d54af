/* The command line parsed: flags (each command accepts its own beside the
 * global --plugin and --help; integers are checked as the line is read),
 * positional arguments, usage errors, and the config as the flags shape
 * it. */
#include <errno.h>
#include <limits.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli/cli.h"
#include "tcb/frames.h"

const cli_flag cli_flags[F_COUNT] = {
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

int cli_fail(const tcb_error *err)
{
    fprintf(stderr, "tcbench: %s\n", err->msg);
    return tcb_status_exit_code(err->code);
}

int cli_usage_error(const char *cmd, const char *fmt, ...)
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
        return cli_usage_error(cmd, "%s: expected an integer from %lld to %lld, got '%s'", cli_flags[f].name, r->min,
                           r->max, s);
    *out = v;
    return 0;
}

long long cli_flag_int(const cli_args *c, int f, long long def) { return c->set[f] ? c->num[f] : def; }

/* --root DATASET=DIR, one per dataset. */
static int add_root(const char *where, const char *value, cli_args *c)
{
    const char *sep = strchr(value, '=');
    size_t n = sep ? (size_t)(sep - value) : 0;
    if (!sep || !n || !sep[1] || n >= sizeof c->root_names[0])
        return cli_usage_error(where, "--root: expected DATASET=DIR, got '%s'", value);
    if (c->n_roots == CLI_MAX_ROOTS) return cli_usage_error(where, "too many --root options");
    memcpy(c->root_names[c->n_roots], value, n);
    c->root_names[c->n_roots][n] = '\0';
    for (int k = 0; k < c->n_roots; k++)
        if (!strcmp(c->root_names[k], c->root_names[c->n_roots]))
            return cli_usage_error(where, "--root: dataset '%s' given twice", c->root_names[k]);
    c->roots[c->n_roots] = (tcb_root_override){c->root_names[c->n_roots], sep + 1};
    c->n_roots++;
    return 0;
}

int cli_parse_flag(const cli_command *cmd, int argc, char **argv, int *i, cli_args *c)
{
    char name[64];
    const char *arg = argv[*i], *eq = strchr(arg, '=');
    size_t len = eq ? (size_t)(eq - arg) : strlen(arg);
    snprintf(name, sizeof name, "%.*s", (int)len, arg);
    if (strcmp(name, "-h") == 0) snprintf(name, sizeof name, "--help");
    int f = 0;
    while (f < F_COUNT && strcmp(cli_flags[f].name, name) != 0) f++;
    unsigned long long accepted = BIT(F_PLUGIN) | BIT(F_HELP) | (cmd ? cmd->accepts : 0);
    const char *where = cmd ? cmd->name : NULL;
    if (f == F_COUNT || !(accepted & BIT(f))) return cli_usage_error(where, "unknown option '%s'", name);
    const char *value = NULL;
    if (cli_flags[f].takes_value) {
        value = eq ? eq + 1 : *i + 1 < argc ? argv[++*i] : NULL;
        if (!value) return cli_usage_error(where, "option '%s' needs a value", name);
    } else if (eq) {
        return cli_usage_error(where, "option '%s' takes no value", name);
    }
    /* A second value would silently replace the first: which one was meant? */
    if (value && c->set[f] && f != F_PLUGIN && f != F_ROOT)
        return cli_usage_error(where, "option '%s' given twice ('%s', then '%s')", name, c->value[f], value);
    int rc = value ? parse_int_flag(where, f, value, &c->num[f]) : 0;
    if (rc) return rc;
    if (f == F_PLUGIN) {
        if (c->n_plugins == CLI_MAX_PLUGINS) return cli_usage_error(where, "too many %s options", name);
        c->plugins[c->n_plugins++] = value;
    }
    if (f == F_ROOT && (rc = add_root(where, value, c))) return rc;
    c->set[f] = 1;
    c->value[f] = value;
    return 0;
}

int cli_parse_command_args(const cli_command *cmd, int argc, char **argv, int i, cli_args *c)
{
    int only_args = 0;
    for (; i < argc; i++) {
        const char *a = argv[i];
        if (!only_args && strcmp(a, "--") == 0) {
            only_args = 1;
        } else if (!only_args && a[0] == '-' && a[1]) {
            int rc = cli_parse_flag(cmd, argc, argv, &i, c);
            if (rc) return rc;
        } else if (c->n_args == cmd->max_args) {
            return cli_usage_error(cmd->name, "unexpected argument '%s'", a);
        } else {
            c->arg[c->n_args++] = a;
        }
    }
    if (!c->set[F_HELP] && c->n_args < cmd->min_args)
        return cli_usage_error(cmd->name, "missing %s", cmd->arg_names);
    return 0;
}

int cli_load_config(const cli_args *c, tcb_config *cfg)
{
    tcb_error err = {0};
    long long threads = cli_flag_int(c, F_THREADS, 0);
    const char *slurm = getenv("SLURM_CPUS_PER_TASK");
    if (!threads && slurm && atoi(slurm) > 0) threads = atoi(slurm);
    tcb_config_opts co = {c->value[F_VARIANT], c->n_roots, c->roots};
    if (tcb_config_load_opts(c->arg[0], &co, cfg, &err)) return cli_fail(&err);
    if (threads > 0) cfg->threads = (int)(threads > 1024 ? 1024 : threads); /* Slurm's may be more */
    return 0;
}
