#include "tcb/json.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "tcb/fsutil.h"

static const char *type_name(const cJSON *j)
{
    if (!j) return "nothing";
    if (cJSON_IsBool(j)) return "a boolean";
    if (cJSON_IsNull(j)) return "null";
    if (cJSON_IsNumber(j)) return "a number";
    if (cJSON_IsString(j)) return "a string";
    if (cJSON_IsArray(j)) return "an array";
    if (cJSON_IsObject(j)) return "an object";
    return "an invalid value";
}

/* "a, b, c" from a NULL-terminated list, for messages. */
static void join_names(const char *const *names, char *out, size_t size)
{
    out[0] = '\0';
    for (; *names; names++) {
        size_t used = strlen(out);
        snprintf(out + used, size - used, "%s%s", used ? ", " : "", *names);
    }
}

int tcb_json_parse(const char *text, const char *origin, cJSON **out, tcb_error *err)
{
    const char *end = NULL;
    *out = cJSON_ParseWithOpts(text, &end, 1);
    if (*out) return TCB_OK;
    int line = 1, col = 1;
    for (const char *p = text; end && p < end && *p; p++) {
        if (*p == '\n') line++, col = 1;
        else col++;
    }
    return tcb_fail(err, TCB_ERR_INPUT, "%s:%d:%d: invalid JSON", origin, line, col);
}

int tcb_json_load(const char *path, cJSON **out, tcb_error *err)
{
    char *text;
    *out = NULL;
    int rc = tcb_read_file(path, &text, NULL, err);
    if (rc) return rc;
    rc = tcb_json_parse(text, path, out, err);
    free(text);
    return rc;
}

int tcb_json_save(const char *path, const cJSON *json, tcb_error *err)
{
    char *text = cJSON_Print(json);
    if (!text) return tcb_fail(err, TCB_ERR_NOMEM, "%s: cannot serialize JSON", path);
    size_t len = strlen(text);
    text[len] = '\n'; /* replace the NUL: files end with a newline */
    int rc = tcb_write_file_atomic(path, text, len + 1, err);
    free(text);
    return rc;
}

int tcb_json_expect_object(const cJSON *obj, const char *where, tcb_error *err)
{
    if (cJSON_IsObject(obj)) return TCB_OK;
    return tcb_fail(err, TCB_ERR_INPUT, "%s: expected an object, got %s", where, type_name(obj));
}

int tcb_json_expect_keys(const cJSON *obj, const char *where, const char *const *allowed,
                         tcb_error *err)
{
    int rc = tcb_json_expect_object(obj, where, err);
    if (rc) return rc;
    for (const cJSON *item = obj->child; item; item = item->next) {
        int known = 0;
        for (const char *const *a = allowed; *a && !known; a++) known = strcmp(*a, item->string) == 0;
        if (!known) {
            char list[512];
            join_names(allowed, list, sizeof list);
            return tcb_fail(err, TCB_ERR_INPUT, "%s.%s: unknown key (expected one of: %s)", where,
                            item->string, list);
        }
    }
    return TCB_OK;
}

/* The item for `key`, or NULL when absent; `missing` is set when it is absent
 * and required, with the error recorded. */
static const cJSON *lookup(const cJSON *obj, const char *key, const char *where, int required,
                           int *rc, tcb_error *err)
{
    *rc = TCB_OK;
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!item && required) *rc = tcb_fail(err, TCB_ERR_INPUT, "%s.%s: required key is missing", where, key);
    return item;
}

int tcb_json_num(const cJSON *obj, const char *key, const char *where, int required, double def,
                 double lo, double hi, double *out, tcb_error *err)
{
    int rc;
    const cJSON *item = lookup(obj, key, where, required, &rc, err);
    *out = def;
    if (rc || !item) return rc;
    if (!cJSON_IsNumber(item))
        return tcb_fail(err, TCB_ERR_INPUT, "%s.%s: expected a number, got %s", where, key, type_name(item));
    double v = item->valuedouble;
    if (!isfinite(v) || v < lo || v > hi)
        return tcb_fail(err, TCB_ERR_INPUT, "%s.%s: %g is out of range [%g, %g]", where, key, v, lo, hi);
    *out = v;
    return TCB_OK;
}

int tcb_json_int(const cJSON *obj, const char *key, const char *where, int required,
                 long long def, long long lo, long long hi, long long *out, tcb_error *err)
{
    int rc;
    const cJSON *item = lookup(obj, key, where, required, &rc, err);
    *out = def;
    if (rc || !item) return rc;
    if (!cJSON_IsNumber(item) || item->valuedouble != floor(item->valuedouble) ||
        fabs(item->valuedouble) > 9007199254740992.0)
        return tcb_fail(err, TCB_ERR_INPUT, "%s.%s: expected an integer, got %s", where, key,
                        cJSON_IsNumber(item) ? "a fractional number" : type_name(item));
    long long v = (long long)item->valuedouble;
    if (v < lo || v > hi)
        return tcb_fail(err, TCB_ERR_INPUT, "%s.%s: %lld is out of range [%lld, %lld]", where, key, v, lo,
                        hi);
    *out = v;
    return TCB_OK;
}

int tcb_json_bool(const cJSON *obj, const char *key, const char *where, int required, int def,
                  int *out, tcb_error *err)
{
    int rc;
    const cJSON *item = lookup(obj, key, where, required, &rc, err);
    *out = def;
    if (rc || !item) return rc;
    if (!cJSON_IsBool(item))
        return tcb_fail(err, TCB_ERR_INPUT, "%s.%s: expected true or false, got %s", where, key,
                        type_name(item));
    *out = cJSON_IsTrue(item);
    return TCB_OK;
}

int tcb_json_str(const cJSON *obj, const char *key, const char *where, int required, const char *def,
                 const char **out, tcb_error *err)
{
    int rc;
    const cJSON *item = lookup(obj, key, where, required, &rc, err);
    *out = def;
    if (rc || !item) return rc;
    if (!cJSON_IsString(item))
        return tcb_fail(err, TCB_ERR_INPUT, "%s.%s: expected a string, got %s", where, key, type_name(item));
    *out = item->valuestring;
    return TCB_OK;
}

int tcb_json_enum(const cJSON *obj, const char *key, const char *where, int required, int def,
                  const char *const *choices, int *index, tcb_error *err)
{
    const char *s;
    *index = def;
    int rc = tcb_json_str(obj, key, where, required, NULL, &s, err);
    if (rc || !s) return rc;
    for (int k = 0; choices[k]; k++)
        if (strcmp(choices[k], s) == 0) return *index = k, TCB_OK;
    char list[512];
    join_names(choices, list, sizeof list);
    return tcb_fail(err, TCB_ERR_INPUT, "%s.%s: unknown value '%s' (expected one of: %s)", where, key, s,
                    list);
}
