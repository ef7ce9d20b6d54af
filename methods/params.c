#include "methods/params.h"

#include <stdlib.h>

#include "tcb/json.h"

int tcb_params_parse(const char *params_json, const char *where, const char *const *allowed,
                     cJSON **out, tcb_error *err)
{
    int rc = tcb_json_parse(params_json && *params_json ? params_json : "{}", where, out, err);
    if (!rc) rc = tcb_json_expect_keys(*out, where, allowed, err);
    if (rc) {
        cJSON_Delete(*out);
        *out = NULL;
    }
    return rc;
}

int tcb_method_create(size_t size, const char *name, const char *params_json,
                      int (*parse)(const char *params_json, void *obj, tcb_error *err),
                      void (*release)(void *obj), void **self, tcb_error *err)
{
    *self = NULL;
    void *obj = calloc(1, size);
    if (!obj) return tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", name);
    int rc = parse(params_json, obj, err);
    if (rc) {
        if (release) release(obj);
        else free(obj);
        return rc;
    }
    *self = obj;
    return TCB_OK;
}
