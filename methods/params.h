/* Parsing a method's params JSON: shared by the built-in methods. */
#ifndef TCB_METHODS_PARAMS_H
#define TCB_METHODS_PARAMS_H

#include <cjson/cJSON.h>

#include "tcb/error.h"

/* Parses params_json (NULL or "" mean "{}"), checks it is an object whose
 * keys are all in the NULL-terminated `allowed`, and returns it in *out (free
 * with cJSON_Delete). `where` (e.g. "nearest.params") prefixes messages. */
int tcb_params_parse(const char *params_json, const char *where, const char *const *allowed,
                     cJSON **out, tcb_error *err);

#endif
