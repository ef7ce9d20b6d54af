#include "methods/params.h"

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
