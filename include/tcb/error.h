/* tcbench — error reporting.
 *
 * Errors travel as a status code plus a one-line message in a caller-owned
 * tcb_error. Library code never prints and never exits; the CLI prints
 * err.msg and maps the code to an exit status (input/IO errors exit 2).
 * A message names the file and line, or the JSON key, that caused it. */
#ifndef TCB_ERROR_H
#define TCB_ERROR_H

#ifdef __cplusplus
extern "C" {
#endif

typedef enum tcb_status {
    TCB_OK = 0,
    TCB_ERR_INPUT = 1,       /* malformed user input: mesh, config, checkpoint */
    TCB_ERR_IO = 2,          /* a path cannot be read or written */
    TCB_ERR_NOMEM = 3,
    TCB_ERR_NUMERIC = 4,     /* NaN/Inf or divergence inside a method */
    TCB_ERR_UNSUPPORTED = 5, /* an optional capability the caller asked for is absent */
    TCB_ERR_INTERNAL = 6,
    TCB_ERR_INTERRUPTED = 7  /* stopped by a signal at a safe point, state saved: rerun to resume */
} tcb_status;

#define TCB_ERRMSG_MAX 1024

typedef struct tcb_error {
    tcb_status code;
    char msg[TCB_ERRMSG_MAX];
} tcb_error;

/* Record an error and return its code, so callers can write
 *     return tcb_fail(err, TCB_ERR_INPUT, "%s:%d: bad vertex", path, line);
 * `err` may be NULL (the message is then dropped). The message is one
 * line: control characters in it (from a quoted key or name) are written
 * as C escapes (\n, \x1b). */
int tcb_fail(tcb_error *err, tcb_status code, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

/* Prepend context ("while loading cat: ") to an already-set message. */
void tcb_error_prefix(tcb_error *err, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));

void tcb_error_clear(tcb_error *err);

/* Short stable name of a status ("input", "io", ...), used in results files. */
const char *tcb_status_name(tcb_status code);

/* The exit status of a run stopped by SIGTERM or SIGUSR1 (Slurm's
 * preemption and --signal) once its state is saved: sysexits' EX_TEMPFAIL,
 * which scripts/slurm/tcbench-array.sbatch requeues on. */
#define TCB_EXIT_INTERRUPTED 75

/* Process exit status for a failed command: 2 for bad input or unreadable
 * paths, 1 otherwise. */
int tcb_status_exit_code(tcb_status code);

#ifdef __cplusplus
}
#endif
#endif
