#include "tcb/hash.h"

#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>

#include "tcb/fsutil.h"

uint64_t tcb_fnv1a64(uint64_t h, const void *data, size_t len)
{
    const unsigned char *p = data;
    for (size_t k = 0; k < len; k++) h = (h ^ p[k]) * 0x100000001b3ULL;
    return h;
}

int tcb_file_fnv1a64(const char *path, size_t *bytes, char hex[17], tcb_error *err)
{
    char *data;
    size_t n;
    int rc = tcb_read_file(path, &data, &n, err);
    if (rc) return rc;
    snprintf(hex, 17, "%016" PRIx64, tcb_fnv1a64(TCB_FNV1A64_OFFSET, data, n));
    free(data);
    if (bytes) *bytes = n;
    return TCB_OK;
}
