/* One run of the user's command (`command... STEP MANIFEST`) and what its
 * end means for the cell: the log gets a header line and everything the
 * command prints; a failure's message says how it ended and quotes the
 * log's last lines, since that is where a traceback is. */
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "methods/external/external.h"
#include "methods/external/process.h"

/* Lines of the log a failure's message quotes, and their share of it. */
#define TAIL_LINES 10
#define TAIL_CHARS 600
/* What the harness puts before a method's message ("prepare_pairs 0-499: "). */
#define TAIL_PREFIX_ROOM 48

/* "python3 icp.py fit" (argv without the manifest), cut to fit out[size]:
 * how messages name the run. */
static void shown_command(char *const *argv, char *out, size_t size)
{
    size_t used = 0;
    out[0] = '\0';
    for (int k = 0; argv[k + 1] && used < size; k++)
        used += (size_t)snprintf(out + used, size - used, "%s%s", k ? " " : "", argv[k]);
}

/* Appends the run's header to the log, the command and the program that
 * runs it; *from: the log's length after it, where the run's own output
 * starts. */
static int log_header(const char *log, const char *shown, const char *program, long *from, tcb_error *err)
{
    FILE *f = fopen(log, "a");
    if (!f) return tcb_fail(err, TCB_ERR_IO, "%s: cannot open the log", log);
    char when[32];
    time_t now = time(NULL);
    struct tm tm;
    strftime(when, sizeof when, "%Y-%m-%dT%H:%M:%SZ", gmtime_r(&now, &tm));
    fprintf(f, "==== tcbench external, %s: %s\n==== program: %s\n", when, shown, program);
    *from = ftell(f);
    return fclose(f) == 0 && *from >= 0 ? TCB_OK : tcb_fail(err, TCB_ERR_IO, "%s: cannot write the log", log);
}

/* How the run ended, as a cell's message and status. */
static int judge(const ext_proc_result *r, const ext_method *m, const char *shown, const char *log, long from,
                 tcb_error *err)
{
    char how[128];
    tcb_status code = TCB_ERR_INPUT;
    if (r->end == EXT_PROC_EXITED && r->status == 0) return TCB_OK;
    if (r->end == EXT_PROC_EXITED && r->status == EXT_EXIT_DIVERGED) {
        code = TCB_ERR_NUMERIC;
        snprintf(how, sizeof how, "exited with status %d: diverged", r->status);
    } else if (r->end == EXT_PROC_EXITED) {
        snprintf(how, sizeof how, "exited with status %d", r->status);
    } else if (r->end == EXT_PROC_SIGNALED) {
        snprintf(how, sizeof how, "was killed by signal %d (%s)", r->status, strsignal(r->status));
    } else if (r->end == EXT_PROC_TIMED_OUT) {
        snprintf(how, sizeof how, "did not finish within timeout_s = %g s and was stopped", m->timeout_s);
    } else {
        code = TCB_ERR_INTERRUPTED;
        snprintf(how, sizeof how, "was stopped by the stop request (SIGTERM, SIGKILL after %g s)", m->grace_s);
    }
    char head[TCB_ERRMSG_MAX], tail[TAIL_CHARS];
    int n = snprintf(head, sizeof head, "`%s` %s after %.1f s (program %s, log %s); ", shown, how, r->wall_s,
                     m->program, log);
    /* The tail gets what the message has left, keeping room for the
     * harness's prefix, so its last line (the exception) is never cut. */
    long room = (long)TCB_ERRMSG_MAX - n - (long)strlen("its last lines: ") - TAIL_PREFIX_ROOM;
    ext_log_tail(log, from, TAIL_LINES, tail, room < 1 ? 1 : room < TAIL_CHARS ? (size_t)room : sizeof tail);
    return tcb_fail(err, code, "%s%s%s", head, tail[0] ? "its last lines: " : "it printed nothing", tail);
}

/* The child's additions to the environment: the cell's thread budget for
 * OpenMP, BLAS and PyTorch, and Python's output unbuffered (unless the user
 * chose), so a killed command's last lines still reach the log. */
static void child_env(const tcb_fit_ctx *ctx, char *threads, size_t size, char **env)
{
    int n = 0;
    snprintf(threads, size, "OMP_NUM_THREADS=%d", ctx->n_threads);
    if (ctx->n_threads > 0) env[n++] = threads;
    if (!getenv("PYTHONUNBUFFERED")) env[n++] = "PYTHONUNBUFFERED=1";
    env[n] = NULL;
}

int ext_run_step(ext_method *m, const char *step, const tcb_fit_ctx *ctx, tcb_error *err)
{
    char log[TCB_PATH_MAX], manifest[TCB_PATH_MAX], program[TCB_PATH_MAX], shown[256], threads[32];
    long from = 0;
    if (tcb_fit_interrupted(ctx))
        return tcb_fail(err, TCB_ERR_INTERRUPTED, "stopped before the command's %s step started", step);
    char **argv = NULL;
    int rc = ext_step_argv(m, step, manifest, &argv, err);
    if (!rc) rc = ext_path(m, EXT_LOG, log, err);
    if (!rc) rc = ext_path(m, EXT_MANIFEST, manifest, err);
    if (!rc) rc = ext_resolve_program(m, argv, program, err);
    if (!rc) shown_command(argv, shown, sizeof shown);
    if (!rc) rc = log_header(log, shown, m->program, &from, err);
    char *env[3];
    child_env(ctx, threads, sizeof threads, env);
    ext_proc_spec spec = {argv, env, log, m->timeout_s, m->grace_s, ctx->interrupted, ctx->interrupt_arg, program};
    ext_proc_result r;
    if (!rc) {
        tcb_report_log(&ctx->reporter, TCB_LOG_INFO, "external: %s (program %s, output in %s)", shown, m->program, log);
        rc = ext_proc_run(&spec, &r, err);
        if (rc) tcb_error_prefix(err, "external.params.command: ");
        rc = ext_name_program(m, rc, err);
    }
    free(argv);
    return rc ? rc : judge(&r, m, shown, log, from, err);
}
