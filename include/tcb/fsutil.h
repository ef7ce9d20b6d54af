/* tcbench — files: atomic writes, whole-file reads, directories.
 *
 * Every output tcbench produces is written to a temporary file in the target
 * directory and renamed into place, so a killed run never leaves a
 * half-written result, cache, split or report behind. */
#ifndef TCB_FSUTIL_H
#define TCB_FSUTIL_H

#include <stddef.h>
#include <stdio.h>

#include "tcb/error.h"

#ifdef __cplusplus
extern "C" {
#endif

#define TCB_PATH_MAX 4096

/* A file being written atomically. Write through `fp`, then commit (flush,
 * fsync, rename over `path`) or abort (close and unlink the temporary). */
typedef struct tcb_atomic_file {
    FILE *fp;
    char path[TCB_PATH_MAX];
    char tmp[TCB_PATH_MAX];
} tcb_atomic_file;

/* Creates missing parent directories of `path`. */
int tcb_atomic_open(tcb_atomic_file *af, const char *path, tcb_error *err);
int tcb_atomic_commit(tcb_atomic_file *af, tcb_error *err);
void tcb_atomic_abort(tcb_atomic_file *af);
/* Abort after a failed write through af->fp: TCB_ERR_IO "<path>: write
 * failed: <the reason>" (a full disk says so). */
int tcb_atomic_fail(tcb_atomic_file *af, tcb_error *err);

/* For writers that need a path rather than a FILE* (HDF5): a unique
 * temporary name next to `path`, and the rename that publishes it. */
int tcb_temp_path_for(const char *path, char *tmp, size_t tmp_size, tcb_error *err);
int tcb_publish(const char *tmp, const char *path, tcb_error *err);

/* Unlinks the temporaries in `dir` whose names start with `prefix` ("" for
 * all) and whose writer has exited: what a killed run left behind. The
 * temporaries of live writers (another tcbench process working on the same
 * run) are kept. */
void tcb_remove_stale_temps(const char *dir, const char *prefix);
/* The same for the temporaries of one file: <path>.tmp-*. */
void tcb_remove_stale_temps_of(const char *path);

int tcb_write_file_atomic(const char *path, const void *data, size_t len,
                          tcb_error *err);

/* Reads the whole file and NUL-terminates it; *data is malloc'ed. */
int tcb_read_file(const char *path, char **data, size_t *len, tcb_error *err);

/* mkdir -p. */
int tcb_mkdirs(const char *path, tcb_error *err);

/* Removes everything below dir, subdirectories included, but not dir
 * itself; links are removed, never followed. A missing dir is empty.
 * Errors name the entry that could not be removed. */
int tcb_empty_dir(const char *dir, tcb_error *err);

int tcb_is_dir(const char *path);
int tcb_is_file(const char *path);

/* snprintf into a path buffer; fails (TCB_ERR_INPUT) instead of truncating. */
int tcb_path_join(char *out, size_t size, tcb_error *err, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));

#ifdef __cplusplus
}
#endif
#endif
