/* tcbench — FNV-1a 64, the one hash of file contents and fingerprints: a
 * check against corruption and mix-ups, not a security measure. Chained:
 * h = tcb_fnv1a64(TCB_FNV1A64_OFFSET, a, la); h = tcb_fnv1a64(h, b, lb). */
#ifndef TCB_HASH_H
#define TCB_HASH_H

#include <stddef.h>
#include <stdint.h>

#include "tcb/error.h"

#ifdef __cplusplus
extern "C" {
#endif

#define TCB_FNV1A64_OFFSET 0xcbf29ce484222325ULL

uint64_t tcb_fnv1a64(uint64_t h, const void *data, size_t len);

/* The FNV-1a 64 of the file at path as 16 hex digits (hex[17]), and its
 * size in *bytes (may be NULL): how a model checkpoint's record and a
 * plug-in's build name a file's contents. */
int tcb_file_fnv1a64(const char *path, size_t *bytes, char hex[17], tcb_error *err);

#ifdef __cplusplus
}
#endif
#endif
