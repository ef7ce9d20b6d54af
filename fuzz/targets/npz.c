/* The .npz results files of `tcbench score` (core/npz.c): the archive's
 * central directory, then every member read, inflated, CRC-checked and
 * parsed as .npy; what is accepted is a parsed array inside its buffer. */
#include "fuzz/fuzz_util.h"
#include "tcb/npz.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *path = fuzz_file("pred.npz", data, size);
    tcb_npz z;
    tcb_error err = {0};
    int rc = tcb_npz_open(path, &z, &err);
    fuzz_check_answer(rc, &err, path);
    if (rc) return 0;
    for (int k = 0; k < z.n; k++) {
        tcb_npy a;
        tcb_error e = {0};
        int r = tcb_npz_read(&z, k, &a, &e);
        fuzz_check_answer(r, &e, path);
        if (!r) {
            fuzz_require(a.data != NULL || a.count == 0, "a parsed member has its data");
            tcb_npy_free(&a);
        }
    }
    tcb_npz_close(&z);
    return 0;
}
