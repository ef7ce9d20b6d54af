/* The cell result reader (store/cell_read.c): what reports, checks
 * and resumption read from a run directory, possibly written elsewhere. */
#include "fuzz/fuzz_util.h"
#include "tcb/results.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *path = fuzz_file("seed_0.json", data, size);
    tcb_cell_result c;
    tcb_error err = {0};
    int rc = tcb_cell_load(path, &c, &err);
    fuzz_check_answer(rc, &err, path);
    if (rc) return 0;
    fuzz_require(c.n_pairs >= 0 && (c.n_pairs == 0 || c.pairs != NULL), "the pairs are there");
    tcb_cell_free(&c);
    return 0;
}
