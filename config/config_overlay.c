/* What the command line changes in a config before it is read: the chosen
 * variant and the dataset roots (tcb_config_opts). Both edit the JSON tree,
 * so the normalized config saved beside the results is the one that ran
 * and reads back without the command line.
 *
 * A variant ("variants": {"cpu": {...}, "paper": {...}}) may replace the
 * seeds and merge params into the methods it names (by label, or by
 * registered method name for every method of that kind); the run goes to
 * <output>/<variant>, so the variants of one config never share cells.
 * A root comes from --root NAME=DIR, else the environment's
 * TCBENCH_ROOT_<NAME> (upper case, other characters as '_'), else the
 * config's own "root". */
#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "config/config_internal.h"
#include "tcb/json.h"

static const char *const variant_keys[] = {"seeds", "params", NULL};

void tcb_config_root_env_name(const char *dataset, char *out, size_t size)
{
    size_t n = (size_t)snprintf(out, size, "TCBENCH_ROOT_");
    for (const char *p = dataset; *p && n + 1 < size; p++)
        out[n++] = isalnum((unsigned char)*p) ? (char)toupper((unsigned char)*p) : '_';
    if (n < size) out[n] = '\0';
}

/* Method's "params" become the patch's keys, then its own keys the patch
 * does not name: the variant's values win, and a preset comes first, the
 * method's own overrides after it (the order the cell records keep). */
static int merge_params(cJSON *method, const cJSON *patch)
{
    cJSON *params = cJSON_GetObjectItemCaseSensitive(method, "params");
    if (params && !cJSON_IsObject(params)) return 0; /* the reader names the bad type */
    cJSON *merged = cJSON_Duplicate(patch, 1);
    if (!merged) return -1;
    for (const cJSON *kv = params ? params->child : NULL; kv; kv = kv->next) {
        if (cJSON_GetObjectItemCaseSensitive(patch, kv->string)) continue;
        cJSON *copy = cJSON_Duplicate(kv, 1);
        if (!copy) {
            cJSON_Delete(merged);
            return -1;
        }
        cJSON_AddItemToObject(merged, kv->string, copy);
    }
    if (params) cJSON_ReplaceItemInObjectCaseSensitive(method, "params", merged);
    else cJSON_AddItemToObject(method, "params", merged);
    return 0;
}

static int method_matches(const cJSON *m, const char *key)
{
    const cJSON *label = cJSON_GetObjectItemCaseSensitive(m, "name");
    const cJSON *impl = cJSON_GetObjectItemCaseSensitive(m, "method");
    if (cJSON_IsString(label) && strcmp(label->valuestring, key) == 0) return 1;
    const cJSON *kind = cJSON_IsString(impl) ? impl : label;
    return cJSON_IsString(kind) && strcmp(kind->valuestring, key) == 0;
}

static int apply_params(cJSON *root, const cJSON *params, const char *where, tcb_error *err)
{
    if (!cJSON_IsObject(params))
        return tcb_fail(err, TCB_ERR_INPUT, "%s.params: expected an object", where);
    cJSON *methods = cJSON_GetObjectItemCaseSensitive(root, "methods");
    for (const cJSON *entry = params->child; entry; entry = entry->next) {
        if (!cJSON_IsObject(entry))
            return tcb_fail(err, TCB_ERR_INPUT, "%s.params.%s: expected an object", where,
                            entry->string);
        int hits = 0;
        cJSON *m;
        cJSON_ArrayForEach(m, methods) {
            if (!cJSON_IsObject(m) || !method_matches(m, entry->string)) continue;
            if (merge_params(m, entry)) return tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", where);
            hits++;
        }
        if (!hits)
            return tcb_fail(err, TCB_ERR_INPUT,
                            "%s.params.%s: no method has that name or label", where, entry->string);
    }
    return TCB_OK;
}

static int set_string(cJSON *obj, const char *key, const char *value)
{
    cJSON *s = cJSON_CreateString(value);
    if (!s) return -1;
    if (cJSON_GetObjectItemCaseSensitive(obj, key)) cJSON_ReplaceItemInObjectCaseSensitive(obj, key, s);
    else cJSON_AddItemToObject(obj, key, s);
    return 0;
}

static void list_variants(const cJSON *variants, char *out, size_t size)
{
    out[0] = '\0';
    for (const cJSON *v = variants->child; v; v = v->next) {
        size_t used = strlen(out);
        snprintf(out + used, size - used, "%s%s", used ? ", " : "", v->string);
    }
}

/* <output>/<variant>, the output defaulting to runs/<name> as the reader does. */
static int variant_output(cJSON *root, const char *variant, const char *top, tcb_error *err)
{
    const cJSON *out = cJSON_GetObjectItemCaseSensitive(root, "output");
    const cJSON *name = cJSON_GetObjectItemCaseSensitive(root, "name");
    if (out && !cJSON_IsString(out))
        return tcb_fail(err, TCB_ERR_INPUT, "%s output: expected a string", top);
    if (!out && !cJSON_IsString(name)) return TCB_OK; /* the reader reports the name */
    char path[TCB_PATH_MAX];
    int n = out ? snprintf(path, sizeof path, "%s/%s", out->valuestring, variant)
                : snprintf(path, sizeof path, "runs/%s/%s", name->valuestring, variant);
    if (n < 0 || (size_t)n >= sizeof path)
        return tcb_fail(err, TCB_ERR_INPUT, "%s output: too long with the variant", top);
    return set_string(root, "output", path) ? tcb_fail(err, TCB_ERR_NOMEM, "%s out of memory", top)
                                            : TCB_OK;
}

static int apply_variant(cJSON *root, const char *origin, const char *wanted, tcb_error *err)
{
    char top[TCB_PATH_MAX + 8], where[TCB_PATH_MAX + 160];
    snprintf(top, sizeof top, "%s:", origin);
    cJSON *variants = cJSON_DetachItemFromObjectCaseSensitive(root, "variants");
    if (!variants) {
        if (wanted)
            return tcb_fail(err, TCB_ERR_INPUT, "%s: --variant %s: the config has no variants", origin,
                            wanted);
        return TCB_OK;
    }
    int rc = TCB_OK;
    const cJSON *v = NULL;
    if (!cJSON_IsObject(variants) || !variants->child)
        rc = tcb_fail(err, TCB_ERR_INPUT, "%s variants: expected an object naming at least one variant",
                      top);
    else if (!(v = wanted ? cJSON_GetObjectItemCaseSensitive(variants, wanted) : variants->child)) {
        char names[512];
        list_variants(variants, names, sizeof names);
        rc = tcb_fail(err, TCB_ERR_INPUT, "%s: --variant %s: unknown (the config has %s)", origin, wanted,
                      names);
    }
    if (!rc) {
        snprintf(where, sizeof where, "%s variants.%s", top, v->string);
        rc = tcb_json_expect_keys(v, where, variant_keys, err);
    }
    const cJSON *seeds = rc ? NULL : cJSON_GetObjectItemCaseSensitive(v, "seeds");
    const cJSON *params = rc ? NULL : cJSON_GetObjectItemCaseSensitive(v, "params");
    if (seeds) {
        cJSON *copy = cJSON_Duplicate(seeds, 1);
        if (!copy) rc = tcb_fail(err, TCB_ERR_NOMEM, "%s out of memory", top);
        else if (cJSON_GetObjectItemCaseSensitive(root, "seeds"))
            cJSON_ReplaceItemInObjectCaseSensitive(root, "seeds", copy);
        else
            cJSON_AddItemToObject(root, "seeds", copy);
    }
    if (!rc && params) rc = apply_params(root, params, where, err);
    if (!rc) rc = variant_output(root, v->string, top, err);
    cJSON_Delete(variants);
    return rc;
}

static cJSON *find_dataset(cJSON *datasets, const char *name)
{
    cJSON *d;
    cJSON_ArrayForEach(d, datasets) {
        const cJSON *n = cJSON_GetObjectItemCaseSensitive(d, "name");
        if (cJSON_IsString(n) && strcmp(n->valuestring, name) == 0) return d;
    }
    return NULL;
}

static int apply_roots(cJSON *root, const char *origin, const tcb_config_opts *o, tcb_error *err)
{
    cJSON *datasets = cJSON_GetObjectItemCaseSensitive(root, "datasets");
    for (int k = 0; k < o->n_roots; k++) {
        cJSON *d = find_dataset(datasets, o->roots[k].dataset);
        if (!d)
            return tcb_fail(err, TCB_ERR_INPUT, "%s: --root %s=...: the config has no dataset '%s'", origin,
                            o->roots[k].dataset, o->roots[k].dataset);
        if (set_string(d, "root", o->roots[k].dir))
            return tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", origin);
    }
    cJSON *d;
    cJSON_ArrayForEach(d, datasets) {
        const cJSON *n = cJSON_GetObjectItemCaseSensitive(d, "name");
        if (!cJSON_IsString(n)) continue;
        int given = 0;
        for (int k = 0; k < o->n_roots; k++) given |= strcmp(o->roots[k].dataset, n->valuestring) == 0;
        char var[128];
        tcb_config_root_env_name(n->valuestring, var, sizeof var);
        const char *env = given ? NULL : getenv(var);
        if (env && *env && set_string(d, "root", env))
            return tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", origin);
    }
    return TCB_OK;
}

int tcb_config_apply_opts(cJSON *root, const char *origin, const tcb_config_opts *o, tcb_error *err)
{
    static const tcb_config_opts none = {0};
    if (!o) o = &none;
    if (!cJSON_IsObject(root)) return TCB_OK; /* the reader reports it */
    int rc = apply_variant(root, origin, o->variant, err);
    return rc ? rc : apply_roots(root, origin, o, err);
}
