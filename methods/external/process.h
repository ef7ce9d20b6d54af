/* Running one external command to its end: no shell, its own process
 * group, output appended to a log file, a timeout and a stop request that
 * end the whole group (SIGTERM, then SIGKILL after a grace period).
 * Nothing here knows tcbench's protocol; methods/external/step.c does. */
#ifndef TCB_METHODS_EXTERNAL_PROCESS_H
#define TCB_METHODS_EXTERNAL_PROCESS_H

#include <stddef.h>

#include "tcb/error.h"

typedef struct ext_proc_spec {
    char *const *argv;          /* NULL-terminated; argv[0] a path (with a '/') or a name looked up in PATH */
    char *const *env_set;       /* "NAME=value" entries that replace or extend the environment; NULL-terminated,
                                 * may be NULL */
    const char *log_path;       /* stdout and stderr are appended to it; stdin is /dev/null */
    double timeout_s;           /* > 0: the command is stopped after so many seconds */
    double grace_s;             /* SIGTERM → SIGKILL delay when it is stopped */
    int (*interrupted)(const void *arg); /* may be NULL; nonzero: stop the command now */
    const void *interrupt_arg;
    const char *path;           /* the executable, as ext_proc_resolve gave it; NULL: argv[0] resolved here */
} ext_proc_spec;

typedef enum ext_proc_end {
    EXT_PROC_EXITED,       /* status: its exit status */
    EXT_PROC_SIGNALED,     /* status: the signal that ended it */
    EXT_PROC_TIMED_OUT,    /* stopped at timeout_s */
    EXT_PROC_INTERRUPTED   /* stopped because interrupted() said so */
} ext_proc_end;

typedef struct ext_proc_result {
    ext_proc_end end;
    int status;
    double wall_s;
} ext_proc_result;

/* Runs the command and waits for it (polling every 10 ms for the timeout
 * and the stop request). When it ends, whatever it left running in its
 * process group is killed: its processes end with it. Fails only when it
 * cannot be started (not found, not executable, the log cannot be opened),
 * naming the command or the log; how it ended is in *r. */
int ext_proc_run(const ext_proc_spec *s, ext_proc_result *r, tcb_error *err);

/* argv[0]'s executable: as given when it has a '/', else the first in
 * $PATH (a missing PATH searches /usr/local/bin:/usr/bin:/bin, as execvp
 * does); TCB_ERR_INPUT naming it when there is none. The path is made
 * absolute against the current directory, symlinks kept (a venv's
 * bin/python is a symlink whose own path tells Python its environment). */
int ext_proc_resolve(const char *name, char *out, size_t size, tcb_error *err);

#endif
