/* The .npy parser (core/npy.c), straight from the buffer: a parsed array's
 * shape multiplies to its count, its data lies inside the buffer, and its
 * elements convert (or are refused) without reading past them. */
#include <stdlib.h>

#include "fuzz/fuzz_util.h"
#include "tcb/npy.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    tcb_npy a;
    tcb_error err = {0};
    int rc = tcb_npy_parse(data, size, &a, &err);
    fuzz_check_answer(rc, &err, NULL);
    if (rc) return 0;
    uint64_t count = 1;
    for (int k = 0; k < a.ndim; k++) count *= a.shape[k];
    fuzz_require(count == a.count, "the shape's product is the count");
    fuzz_require(a.data >= data && a.data + a.count * (uint64_t)a.item_size == data + size,
                 "the elements end the buffer");
    if (a.count > (1u << 20)) return 0; /* a valid header of a large array: nothing more to learn */
    int64_t *ids = malloc((a.count ? a.count : 1) * sizeof *ids);
    double *xs = malloc((a.count ? a.count : 1) * sizeof *xs);
    fuzz_require(ids && xs, "memory");
    tcb_error e2 = {0};
    fuzz_check_answer(tcb_npy_to_int64(&a, ids, &e2), &e2, NULL);
    tcb_error e3 = {0};
    fuzz_check_answer(tcb_npy_to_double(&a, xs, &e3), &e3, NULL);
    free(ids);
    free(xs);
    return 0;
}
