/* The regression baseline reader (reports/baseline.c), which `tcbench
 * check` trusts: tolerances are finite and not negative. */
#include <math.h>

#include "fuzz/fuzz_util.h"
#include "reports/baseline.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *path = fuzz_file("baseline.json", data, size);
    tcb_baseline b;
    tcb_error err = {0};
    int rc = tcb_baseline_load(path, &b, &err);
    fuzz_check_answer(rc, &err, path);
    if (rc) return 0;
    for (int r = 0; r < b.n_rows; r++)
        for (int m = 0; m < TCB_N_METRICS; m++)
            fuzz_require(b.rows[r].abs_tol[m] >= 0 && b.rows[r].rel_tol[m] >= 0 && isfinite(b.rows[r].abs_tol[m]) &&
                             isfinite(b.rows[r].rel_tol[m]),
                         "tolerances are finite and not negative");
    tcb_baseline_free(&b);
    return 0;
}
