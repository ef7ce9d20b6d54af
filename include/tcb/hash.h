/* tcbench — FNV-1a 64, the one hash of file contents and fingerprints: a
 * check against corruption and mix-ups, not a security measure. Chained:
 * h = tcb_fnv1a64(TCB_FNV1A64_OFFSET, a, la); h = tcb_fnv1a64(h, b, lb). */
#ifndef TCB_HASH_H
#define TCB_HASH_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define TCB_FNV1A64_OFFSET 0xcbf29ce484222325ULL

uint64_t tcb_fnv1a64(uint64_t h, const void *data, size_t len);

#ifdef __cplusplus
}
#endif
#endif
