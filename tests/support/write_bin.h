/* Test helpers' raw array files: bytes as they are in memory (little-endian
 * here), read back by numpy.fromfile. Header-only: the dump programs link
 * nothing else of tests/support. */
#ifndef TCB_TEST_WRITE_BIN_H
#define TCB_TEST_WRITE_BIN_H

#include <stdio.h>

#include "tcb/error.h"
#include "tcb/fsutil.h"

/* DIR/NAME := data[0 .. bytes) (mode "wb"), or data appended ("ab"). */
static inline int tcb_test_put_bin(const char *dir, const char *name, const void *data, size_t bytes,
                                   const char *mode, tcb_error *err)
{
    char path[TCB_PATH_MAX];
    int rc = tcb_path_join(path, sizeof path, err, "%s/%s", dir, name);
    if (rc) return rc;
    FILE *f = fopen(path, mode);
    if (!f || fwrite(data, 1, bytes, f) != bytes || fclose(f))
        return tcb_fail(err, TCB_ERR_IO, "%s: cannot write", path);
    return TCB_OK;
}

/* DIR/NAME := data[0 .. bytes). */
static inline int tcb_test_write_bin(const char *dir, const char *name, const void *data, size_t bytes,
                                     tcb_error *err)
{
    return tcb_test_put_bin(dir, name, data, bytes, "wb", err);
}

#endif
