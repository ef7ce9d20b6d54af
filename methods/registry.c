/* The method registry: the built-in tables plus plug-ins loaded by path.
 * The only process-wide mutable state in libtcbench (the brief allows it
 * here); it grows only, and plug-ins stay loaded for the process lifetime
 * because their tables and code are referenced until exit. */
#include "tcb/registry.h"

#include <dlfcn.h>
#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "methods/builtin.h"
#include "tcb/hash.h"
#include "tcb/version.h"

#define MAX_METHODS 256

static const tcb_method_ops *const builtins[] = {
    &tcb_method_oracle,
    &tcb_method_nearest,
    &tcb_method_nricp,
    &tcb_method_atlasnet,
    &tcb_method_dsr,
    &tcb_method_mca,
    &tcb_method_cc,
    &tcb_method_neupig,
    &tcb_method_pdg,
    &tcb_method_dynosurf,
    &tcb_method_external,
};
#define N_BUILTINS ((int)(sizeof builtins / sizeof builtins[0]))

typedef struct plugin_entry {
    const tcb_method_ops *ops;
    char *origin;     /* the plug-in's path, resolved (realpath) */
    char digest[17];  /* FNV-1a 64 of the file, hex: which build of it ran */
} plugin_entry;

static plugin_entry plugins[MAX_METHODS];
static int n_plugins;

int tcb_registry_count(void) { return N_BUILTINS + n_plugins; }

const tcb_method_ops *tcb_registry_get(int k)
{
    if (k < 0 || k >= tcb_registry_count()) return NULL;
    return k < N_BUILTINS ? builtins[k] : plugins[k - N_BUILTINS].ops;
}

const char *tcb_registry_origin(int k)
{
    if (k < 0 || k >= tcb_registry_count()) return NULL;
    return k < N_BUILTINS ? "built-in" : plugins[k - N_BUILTINS].origin;
}

const tcb_method_ops *tcb_registry_find(const char *name)
{
    for (int k = 0; k < tcb_registry_count(); k++)
        if (strcmp(tcb_registry_get(k)->name, name) == 0) return tcb_registry_get(k);
    return NULL;
}

const char *tcb_registry_digest(const tcb_method_ops *ops)
{
    for (int k = 0; k < n_plugins; k++)
        if (plugins[k].ops == ops) return plugins[k].digest;
    return NULL;
}

const char *tcb_registry_file(const tcb_method_ops *ops)
{
    for (int k = 0; k < n_plugins; k++)
        if (plugins[k].ops == ops) return plugins[k].origin;
    return NULL;
}

/* [a-z0-9_]+, as tcb/method.h promises: a name is a word in configs,
 * directories and tables. */
static int valid_name(const char *name)
{
    if (!name || !*name || strlen(name) >= 64) return 0;
    for (const char *p = name; *p; p++)
        if (!((*p >= 'a' && *p <= 'z') || (*p >= '0' && *p <= '9') || *p == '_')) return 0;
    return 1;
}

/* The first of the functions every method must define that ops lacks. */
static const char *missing_function(const tcb_method_ops *ops)
{
    return !ops->create ? "create" : !ops->fit ? "fit" : !ops->transfer ? "transfer" : !ops->destroy ? "destroy" : NULL;
}

/* A table must be complete enough for the harness to call it blindly. */
static int check_table(const tcb_method_ops *ops, const char *path, tcb_error *err)
{
    if (!ops) return tcb_fail(err, TCB_ERR_INPUT, "%s: plug-in returned a NULL method table", path);
    if (ops->abi_version < TCB_METHOD_ABI_OLDEST || ops->abi_version > TCB_METHOD_ABI_VERSION)
        return tcb_fail(err, TCB_ERR_INPUT,
                        "%s: method ABI version %d, this tcbench (%s) reads %d to %d: rebuild the plug-in against "
                        "this tcbench's headers (<prefix>/include/tcb/method.h of its install, or include/ of its "
                        "source tree)",
                        path, ops->abi_version, TCB_VERSION, TCB_METHOD_ABI_OLDEST, TCB_METHOD_ABI_VERSION);
    if (!valid_name(ops->name))
        return tcb_fail(err, TCB_ERR_INPUT, "%s: method name '%s' must be 1-63 characters of [a-z0-9_]", path,
                        ops->name ? ops->name : "(null)");
    const char *missing = missing_function(ops);
    if (missing)
        return tcb_fail(err, TCB_ERR_INPUT, "%s: method '%s' has no %s (create, fit, transfer and destroy are required)",
                        path, ops->name, missing);
    if (!ops->save != !ops->load)
        return tcb_fail(err, TCB_ERR_INPUT, "%s: method '%s' must define both save and load, or neither", path,
                        ops->name);
    const tcb_method_ops *other = tcb_registry_find(ops->name);
    if (other)
        return tcb_fail(err, TCB_ERR_INPUT, "%s: a method named '%s' is already registered from %s", path, ops->name,
                        tcb_registry_file(other) ? tcb_registry_file(other) : "tcbench itself (built in)");
    return TCB_OK;
}

int tcb_registry_load_plugin(const char *path, tcb_error *err)
{
    /* One file is one plug-in however it is named (--plugin and a config's
     * "plugins" may name it relatively and absolutely): compared resolved. */
    char full[PATH_MAX];
    if (!realpath(path, full)) return tcb_fail(err, TCB_ERR_INPUT, "%s: cannot load plug-in: %s", path, strerror(errno));
    for (int k = 0; k < n_plugins; k++)
        if (strcmp(plugins[k].origin, full) == 0) return TCB_OK; /* already loaded */
    char digest[17];
    int rc = tcb_file_fnv1a64(full, NULL, digest, err);
    if (rc) return rc;
    void *handle = dlopen(full, RTLD_NOW | RTLD_LOCAL);
    if (!handle) return tcb_fail(err, TCB_ERR_INPUT, "%s: cannot load plug-in: %s", path, dlerror());
    tcb_plugin_entry_fn entry;
    *(void **)&entry = dlsym(handle, TCB_PLUGIN_ENTRY); /* POSIX-sanctioned cast of a data pointer */
    if (!entry) {
        dlclose(handle);
        return tcb_fail(err, TCB_ERR_INPUT, "%s: not a tcbench plug-in (no symbol %s)", path, TCB_PLUGIN_ENTRY);
    }
    int count = 0;
    const tcb_method_ops *const *tables = entry(&count);
    if (!tables || count <= 0 || n_plugins + count > MAX_METHODS) {
        dlclose(handle);
        return tcb_fail(err, TCB_ERR_INPUT, "%s: plug-in offers %d methods (expected 1..%d)", path, count,
                        MAX_METHODS - n_plugins);
    }
    for (int k = 0; k < count; k++) {
        rc = check_table(tables[k], path, err);
        for (int m = 0; !rc && m < k; m++)
            if (strcmp(tables[m]->name, tables[k]->name) == 0)
                rc = tcb_fail(err, TCB_ERR_INPUT, "%s: method '%s' is listed twice", path, tables[k]->name);
        if (rc) {
            dlclose(handle);
            return rc;
        }
    }
    for (int k = 0; k < count; k++) {
        plugins[n_plugins].ops = tables[k];
        plugins[n_plugins].origin = strdup(full);
        memcpy(plugins[n_plugins].digest, digest, sizeof digest);
        n_plugins++;
    }
    return TCB_OK;
}
