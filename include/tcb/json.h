/* tcbench — JSON helpers over cJSON with errors that name the key.
 *
 * `where` is the path of the object being read, for messages, e.g.
 * "configs/quick.json: methods[1].params"; a failing getter reports
 * "configs/quick.json: methods[1].params.lr: expected a number, got a string". */
#ifndef TCB_JSON_H
#define TCB_JSON_H

#include <stdint.h>
#include <cjson/cJSON.h>

#include "tcb/error.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Parse a file; a syntax error reports "file:line:col: invalid JSON". */
int tcb_json_load(const char *path, cJSON **out, tcb_error *err);
/* Parse text; `origin` names it in messages. */
int tcb_json_parse(const char *text, const char *origin, cJSON **out, tcb_error *err);
/* Pretty-print and write atomically. */
int tcb_json_save(const char *path, const cJSON *json, tcb_error *err);

/* Fails on any key of `obj` not in the NULL-terminated list `allowed`. */
int tcb_json_expect_keys(const cJSON *obj, const char *where,
                         const char *const *allowed, tcb_error *err);
/* Fails unless `obj` is a JSON object. */
int tcb_json_expect_object(const cJSON *obj, const char *where, tcb_error *err);

/* Typed getters. A missing key gives `def` unless `required`; a present key
 * of the wrong type or out of [lo, hi] is an error. */
int tcb_json_int(const cJSON *obj, const char *key, const char *where, int required,
                 long long def, long long lo, long long hi, long long *out,
                 tcb_error *err);
int tcb_json_num(const cJSON *obj, const char *key, const char *where, int required,
                 double def, double lo, double hi, double *out, tcb_error *err);
int tcb_json_bool(const cJSON *obj, const char *key, const char *where, int required,
                  int def, int *out, tcb_error *err);
/* *out points into `obj` (or is `def`); copy it if it must outlive obj. */
int tcb_json_str(const cJSON *obj, const char *key, const char *where, int required,
                 const char *def, const char **out, tcb_error *err);
/* A string that must be one of the NULL-terminated `choices`; *index is its position. */
int tcb_json_enum(const cJSON *obj, const char *key, const char *where, int required,
                  int def, const char *const *choices, int *index, tcb_error *err);

#ifdef __cplusplus
}
#endif
#endif
