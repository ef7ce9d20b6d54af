/* Private to config/: the steps the reader applies to a config's JSON tree
 * before it reads it (tcb/config.h is the room's face). */
#ifndef TCB_CONFIG_INTERNAL_H
#define TCB_CONFIG_INTERNAL_H

#include <cjson/cJSON.h>

#include "tcb/config.h"

/* The chosen variant and the roots applied to a config's JSON tree before
 * it is read (config/config_overlay.c). */
int tcb_config_apply_opts(cJSON *root, const char *origin, const tcb_config_opts *o, tcb_error *err);

/* Relative paths to code ("plugins", an external method's command) made
 * absolute against the directory of the config file `origin`; nothing
 * changes when origin names no file (config/config_paths.c). */
int tcb_config_resolve_paths(cJSON *root, const char *origin, tcb_error *err);

#endif
