/* Which program a step runs, and saying so. A command whose program is a
 * Python script runs under the interpreter the user chose (external.h has
 * the order), not whatever `python3` is first on PATH; whichever program
 * runs is resolved to an absolute path before it starts, and the log and
 * every failure name that path: "ModuleNotFoundError: numpy" means little
 * until one sees it came from a shim on PATH. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "methods/external/external.h"
#include "methods/external/process.h"

int ext_is_script(const char *program)
{
    size_t n = strlen(program);
    return n > 3 && !strcmp(program + n - 3, ".py");
}

int ext_step_argv(const ext_method *m, const char *step, const char *manifest, char ***argv, tcb_error *err)
{
    int first = ext_is_script(m->command[0]);
    char **a = calloc((size_t)m->n_command + 4, sizeof *a);
    if (!a) return tcb_fail(err, TCB_ERR_NOMEM, "external: out of memory");
    if (first) a[0] = m->python ? m->python : EXT_PYTHON_DEFAULT;
    memcpy(a + first, m->command, (size_t)m->n_command * sizeof *a);
    a[first + m->n_command] = (char *)step, a[first + m->n_command + 1] = (char *)manifest;
    *argv = a;
    return TCB_OK;
}

int ext_resolve_program(ext_method *m, char *const *argv, char *path, tcb_error *err)
{
    int script = ext_is_script(m->command[0]), lookup = !strchr(argv[0], '/');
    int rc = ext_proc_resolve(argv[0], path, TCB_PATH_MAX, err);
    if (rc && !script) tcb_error_prefix(err, "external.params.command: ");
    else if (rc && m->python_from) tcb_error_prefix(err, "%s (the interpreter of %s): ", m->python_from, m->command[0]);
    else if (rc)
        tcb_error_prefix(err, "the interpreter of %s (set %s or external.params.python to choose one): ", m->command[0],
                         EXT_PYTHON_ENV);
    if (rc) return rc;
    /* "/usr/bin/python3 [python3 from PATH]", "/venv/bin/python [TCBENCH_PYTHON]", "/abs/run.sh" */
    const char *from = script ? m->python_from : NULL;
    char found[TCB_PATH_MAX + 16] = "";
    if (lookup) snprintf(found, sizeof found, "%s from PATH", argv[0]);
    if (from || lookup)
        snprintf(m->program, sizeof m->program, "%s [%s%s%s]", path, from ? from : "", from && lookup ? ", " : "", found);
    else
        snprintf(m->program, sizeof m->program, "%s", path);
    return TCB_OK;
}

int ext_name_program(const ext_method *m, int rc, tcb_error *err)
{
    if (rc == TCB_OK || rc == TCB_ERR_INTERRUPTED || rc == TCB_ERR_UNSUPPORTED || !m->program[0] || !err) return rc;
    size_t len = strnlen(err->msg, sizeof err->msg);
    snprintf(err->msg + len, sizeof err->msg - len, "; program: %s", m->program);
    return rc;
}
