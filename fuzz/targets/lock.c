/* The cell lock reader (harness/cell_lock.c): a lock file comes from any
 * host sharing the run directory, and whatever it holds, reading it must
 * give a holder to report or "unreadable", never a crash. */
#include <stdio.h>
#include <string.h>

#include "fuzz/fuzz_util.h"
#include "harness/harness_internal.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fuzz_file("seed_0.json.lock", data, size);
    char cell[TCB_PATH_MAX];
    snprintf(cell, sizeof cell, "%s/seed_0.json", fuzz_dir());
    tcb_lock_info info;
    fuzz_require(tcb_cell_lock_holder(cell, &info) == 0, "a lock file present is read");
    fuzz_require(memchr(info.host, '\0', sizeof info.host) != NULL, "the host is a string");
    return 0;
}
