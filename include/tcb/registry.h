/* tcbench — the method registry: built-in methods plus plug-ins loaded by
 * path. This is the only process-wide mutable state in libtcbench. */
#ifndef TCB_REGISTRY_H
#define TCB_REGISTRY_H

#include "tcb/error.h"
#include "tcb/method.h"

#ifdef __cplusplus
extern "C" {
#endif

const tcb_method_ops *tcb_registry_find(const char *name);
int tcb_registry_count(void);
const tcb_method_ops *tcb_registry_get(int k);
/* Where method k came from: "built-in" or the plug-in's path (resolved). */
const char *tcb_registry_origin(int k);
/* The FNV-1a 64 digest (16 hex digits) of the plug-in file a method table
 * came from, read when it was loaded; NULL for a built-in method. A run
 * directory records it, so that a rebuilt plug-in is noticed. */
const char *tcb_registry_digest(const tcb_method_ops *ops);
/* The plug-in file (resolved) a method table came from; NULL for a
 * built-in method. */
const char *tcb_registry_file(const tcb_method_ops *ops);

/* dlopen a plug-in and register its methods. Fails on a missing entry
 * symbol, a wrong abi_version, an incomplete table or a name already
 * registered (naming the file it came from). The same file, however
 * named, is loaded once. */
int tcb_registry_load_plugin(const char *path, tcb_error *err);

#ifdef __cplusplus
}
#endif
#endif
