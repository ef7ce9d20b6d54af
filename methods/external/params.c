/* external.params: the command as an argv list (no shell: what is listed
 * is what runs, quoting never matters), the interpreter of a .py command,
 * its time limit and the grace a stopped command gets to save its state. */
#include <stdlib.h>
#include <string.h>

#include "methods/external/external.h"
#include "methods/params.h"
#include "tcb/json.h"

#define WHERE "external.params"
/* Most arguments a command may list: beyond, it is a mistake, not a method. */
#define MAX_ARGS 256
#define DEFAULT_GRACE_S 10.0

/* params.command into m->command: a non-empty list of non-empty strings. */
static int parse_command(const cJSON *json, ext_method *m, tcb_error *err)
{
    const cJSON *c = cJSON_GetObjectItemCaseSensitive(json, "command");
    if (!c) return tcb_fail(err, TCB_ERR_INPUT, WHERE ".command: required (a list: program and arguments)");
    int n = cJSON_IsArray(c) ? cJSON_GetArraySize(c) : -1;
    if (n < 1 || n > MAX_ARGS)
        return tcb_fail(err, TCB_ERR_INPUT, WHERE ".command: expected a list of 1 to %d strings (program and arguments)",
                        MAX_ARGS);
    m->command = calloc((size_t)n + 1, sizeof *m->command);
    if (!m->command) return tcb_fail(err, TCB_ERR_NOMEM, "external: out of memory");
    m->n_command = n;
    int k = 0;
    for (const cJSON *it = c->child; it; it = it->next, k++) {
        if (!cJSON_IsString(it) || !it->valuestring[0])
            return tcb_fail(err, TCB_ERR_INPUT, WHERE ".command[%d]: expected a non-empty string", k);
        if (!(m->command[k] = strdup(it->valuestring))) return tcb_fail(err, TCB_ERR_NOMEM, "external: out of memory");
    }
    return TCB_OK;
}

/* The interpreter of a .py command: params.python (this method's, so it
 * wins), else $TCBENCH_PYTHON (the machine's), else none: python3 from PATH
 * when the step runs. params.python beside a command that is not a .py
 * script would be silently unused: refused. */
static int parse_python(const cJSON *json, ext_method *m, tcb_error *err)
{
    const cJSON *p = cJSON_GetObjectItemCaseSensitive(json, "python");
    const char *env = getenv(EXT_PYTHON_ENV), *value = NULL;
    if (p && (!cJSON_IsString(p) || !p->valuestring[0]))
        return tcb_fail(err, TCB_ERR_INPUT, WHERE ".python: expected a non-empty string (the interpreter of .py commands)");
    if (p && !ext_is_script(m->command[0]))
        return tcb_fail(err, TCB_ERR_INPUT,
                        WHERE ".python: runs .py commands, but command[0] '%s' is not a .py script (list the script "
                        "first: [\"method.py\", ...])", m->command[0]);
    if (p) value = p->valuestring, m->python_from = WHERE ".python";
    else if (env && env[0]) value = env, m->python_from = EXT_PYTHON_ENV;
    if (value && !(m->python = strdup(value))) return tcb_fail(err, TCB_ERR_NOMEM, "external: out of memory");
    return TCB_OK;
}

int ext_params_parse(const char *params_json, ext_method *m, tcb_error *err)
{
    static const char *const keys[] = {"command", "python", "timeout_s", "grace_s", NULL};
    cJSON *json;
    int rc = tcb_params_parse(params_json, WHERE, keys, &json, err);
    if (rc) return rc;
    rc = parse_command(json, m, err);
    if (!rc) rc = parse_python(json, m, err);
    if (!rc) rc = tcb_json_num(json, "timeout_s", WHERE, 0, 0, 0, 1e9, &m->timeout_s, err);
    if (!rc) rc = tcb_json_num(json, "grace_s", WHERE, 0, DEFAULT_GRACE_S, 0, 3600, &m->grace_s, err);
    cJSON_Delete(json);
    return rc;
}

char *ext_command_json(const ext_method *m)
{
    cJSON *a = cJSON_CreateStringArray((const char *const *)m->command, m->n_command);
    char *text = a ? cJSON_PrintUnformatted(a) : NULL;
    cJSON_Delete(a);
    return text;
}
