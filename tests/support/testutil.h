/* Small helpers shared by the unit tests. */
#ifndef TCB_TESTUTIL_H
#define TCB_TESTUTIL_H

#include <stddef.h>

/* Creates a fresh directory under $TMPDIR (or /tmp) and writes its path to
 * out; aborts the test program on failure. */
void tu_make_tmpdir(char *out, size_t size);

/* Writes text to dir/name (creating it); returns the full path in out. */
void tu_write_text(const char *dir, const char *name, const char *text, char *out,
                   size_t size);

/* rm -rf of a directory made by tu_make_tmpdir. */
void tu_remove_tree(const char *dir);

/* Path of the shared real data (../shared/data), or NULL when absent. */
const char *tu_shared_data(void);

#endif
