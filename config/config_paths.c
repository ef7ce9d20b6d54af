/* Paths to code in a config resolve against the config file's directory,
 * not the directory tcbench runs in: a config names its plug-ins and its
 * external methods' programs beside it, and `tcbench inspect`, `frames` or
 * `run` from another directory must find the same code.
 *
 * Rewritten to absolute paths before the config is read, so that the
 * normalized config (and the run directory's record of it, which
 * `inspect` and `frames` read back from another place) names the very
 * files that ran:
 *   - "plugins": every relative path;
 *   - an external method's "params.command": a relative element that
 *     names an existing file beside the config (the script in ["python3",
 *     "my_method.py"], a program "./run.sh"); the program itself only when
 *     it has a '/' or is a .py script (another bare name is looked up in
 *     PATH as before), and an argument that names no file there is left
 *     as written; "params.python" as the program is.
 * Data and output locations ("output", "splits_dir", "cache_dir", a
 * dataset's "root") stay relative to the current directory: the shipped
 * configs and the README run from the repository root with "output":
 * "runs/quick", and a run directory's place is the user's, not the
 * config's. */
#include <limits.h>
#include <stdlib.h>
#include <string.h>

#include "config/config_internal.h"
#include "tcb/fsutil.h"

/* The config file's directory, absolute, in dir; 0 when origin names no
 * file (a config parsed from text): its paths are then left as written. */
static int config_dir(const char *origin, char *dir, size_t size)
{
    char copy[TCB_PATH_MAX], abs[PATH_MAX];
    if (!tcb_is_file(origin) || (size_t)snprintf(copy, sizeof copy, "%s", origin) >= sizeof copy) return 0;
    char *slash = strrchr(copy, '/');
    if (slash) *slash = '\0';
    if (!realpath(slash ? (copy[0] ? copy : "/") : ".", abs)) return 0;
    return (size_t)snprintf(dir, size, "%s", abs) < size;
}

/* Replaces the string item with dir/its value when it is relative and
 * (with must_exist) names a file there. */
static int resolve(cJSON *item, const char *dir, int must_exist, const char *where, tcb_error *err)
{
    if (!cJSON_IsString(item) || !item->valuestring[0] || item->valuestring[0] == '/') return TCB_OK;
    char path[TCB_PATH_MAX];
    int rc = tcb_path_join(path, sizeof path, err, "%s/%s", dir, item->valuestring);
    if (rc) {
        tcb_error_prefix(err, "%s: ", where);
        return rc;
    }
    if (must_exist && !tcb_is_file(path)) return TCB_OK;
    return cJSON_SetValuestring(item, path) ? TCB_OK : tcb_fail(err, TCB_ERR_NOMEM, "out of memory");
}

static int is_external(const cJSON *method)
{
    const cJSON *impl = cJSON_GetObjectItemCaseSensitive(method, "method");
    if (!impl) impl = cJSON_GetObjectItemCaseSensitive(method, "name");
    return cJSON_IsString(impl) && strcmp(impl->valuestring, "external") == 0;
}

/* A program named as a file: with a '/', or a .py script (which the
 * external method runs under its interpreter); a bare name is PATH's. */
static int names_a_file(const cJSON *program)
{
    if (!cJSON_IsString(program)) return 0;
    const char *name = program->valuestring;
    size_t n = strlen(name);
    return strchr(name, '/') || (n > 3 && strcmp(name + n - 3, ".py") == 0);
}

int tcb_config_resolve_paths(cJSON *root, const char *origin, tcb_error *err)
{
    char dir[TCB_PATH_MAX];
    if (!config_dir(origin, dir, sizeof dir)) return TCB_OK;
    int rc = TCB_OK;
    const cJSON *plugins = cJSON_GetObjectItemCaseSensitive(root, "plugins");
    for (cJSON *p = cJSON_IsArray(plugins) ? plugins->child : NULL; p && !rc; p = p->next)
        rc = resolve(p, dir, 0, origin, err);
    const cJSON *methods = cJSON_GetObjectItemCaseSensitive(root, "methods");
    for (cJSON *m = cJSON_IsArray(methods) ? methods->child : NULL; m && !rc; m = m->next) {
        if (!is_external(m)) continue;
        const cJSON *params = cJSON_GetObjectItemCaseSensitive(m, "params");
        const cJSON *command = cJSON_GetObjectItemCaseSensitive(params, "command");
        for (cJSON *e = cJSON_IsArray(command) ? command->child : NULL; e && !rc; e = e->next)
            if (e != command->child || names_a_file(e)) rc = resolve(e, dir, 1, origin, err);
        if (!rc && names_a_file(cJSON_GetObjectItemCaseSensitive(params, "python")))
            rc = resolve(cJSON_GetObjectItemCaseSensitive(params, "python"), dir, 1, origin, err);
    }
    return rc;
}
