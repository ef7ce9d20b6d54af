#include "tcb/hash.h"

uint64_t tcb_fnv1a64(uint64_t h, const void *data, size_t len)
{
    const unsigned char *p = data;
    for (size_t k = 0; k < len; k++) h = (h ^ p[k]) * 0x100000001b3ULL;
    return h;
}
