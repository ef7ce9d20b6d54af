/* Parsing a method's params JSON: shared by the built-in methods. */
#ifndef TCB_METHODS_PARAMS_H
#define TCB_METHODS_PARAMS_H

#include <stddef.h>

#include <cjson/cJSON.h>

#include "tcb/error.h"

/* Parses params_json (NULL or "" mean "{}"), checks it is an object whose
 * keys are all in the NULL-terminated `allowed`, and returns it in *out (free
 * with cJSON_Delete). `where` (e.g. "nearest.params") prefixes messages. */
int tcb_params_parse(const char *params_json, const char *where, const char *const *allowed,
                     cJSON **out, tcb_error *err);

/* A method's usual `create`: a zeroed object of `size` bytes, its params
 * parsed into it by `parse`; on failure `release` (NULL: free) disposes of
 * what parse may have filled and *self stays NULL. `name` is for the
 * out-of-memory message. */
int tcb_method_create(size_t size, const char *name, const char *params_json,
                      int (*parse)(const char *params_json, void *obj, tcb_error *err),
                      void (*release)(void *obj), void **self, tcb_error *err);

#endif
