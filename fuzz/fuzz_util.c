#include "fuzz/fuzz_util.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "tcb/fsutil.h"
#include "tcb/hash.h"

/* libFuzzer calls the target with no context to carry state in, so the
 * scratch directory is the one process-wide variable: created on first
 * use, removed by atexit. */
static char scratch[TCB_PATH_MAX];

static void remove_scratch(void)
{
    tcb_error err = {0};
    if (tcb_empty_dir(scratch, &err) == TCB_OK) remove(scratch);
}

const char *fuzz_dir(void)
{
    if (scratch[0]) return scratch;
    /* In memory when it can be: a target writes a file per input, and on a
     * disk-backed /tmp that alone made the OBJ target 9x slower. */
    const char *tmp = getenv("TMPDIR");
    if (!tmp || !tmp[0]) tmp = tcb_is_dir("/dev/shm") && access("/dev/shm", W_OK) == 0 ? "/dev/shm" : "/tmp";
    tcb_error err = {0};
    if (tcb_path_join(scratch, sizeof scratch, &err, "%s/tcbench-fuzz-XXXXXX", tmp)) {
        fprintf(stderr, "%s\n", err.msg);
        abort();
    }
    if (!mkdtemp(scratch)) {
        perror(scratch);
        abort();
    }
    atexit(remove_scratch);
    return scratch;
}

const char *fuzz_file(const char *name, const uint8_t *data, size_t size)
{
    static char path[TCB_PATH_MAX];
    tcb_error err = {0};
    if (tcb_path_join(path, sizeof path, &err, "%s/%s", fuzz_dir(), name)) {
        fprintf(stderr, "%s\n", err.msg);
        abort();
    }
    FILE *fp = fopen(path, "wb");
    if (!fp || fwrite(data, 1, size, fp) != size || fclose(fp)) {
        perror(path);
        abort();
    }
    return path;
}

const char *fuzz_file_checksummed(const char *name, const uint8_t *data, size_t size)
{
    uint8_t *copy = malloc(size + 1);
    fuzz_require(copy != NULL, "memory");
    memcpy(copy, data, size);
    if (size >= 8) {
        uint64_t h = tcb_fnv1a64(TCB_FNV1A64_OFFSET, copy, size - 8);
        memcpy(copy + size - 8, &h, 8);
    }
    const char *path = fuzz_file(name, copy, size);
    free(copy);
    return path;
}

void fuzz_require(int cond, const char *what)
{
    if (cond) return;
    fprintf(stderr, "fuzz invariant broken: %s\n", what);
    abort();
}

void fuzz_check_answer(int rc, const tcb_error *err, const char *path)
{
    if (getenv("TCB_FUZZ_VERBOSE")) fprintf(stderr, "answer: %s\n", rc ? err->msg : "accepted");
    if (rc == TCB_OK) return;
    fuzz_require(err->code == (tcb_status)rc, "the error's code is the status returned");
    fuzz_require(err->msg[0] != '\0', "a failure comes with a message");
    fuzz_require(strchr(err->msg, '\n') == NULL, "the message is one line");
    if (path && !strstr(err->msg, path)) {
        fprintf(stderr, "message without the file's name %s: %s\n", path, err->msg);
        abort();
    }
}

void fuzz_check_point_frame(int rc, const tcb_error *err, const char *path, float *pts, int n, int want)
{
    fuzz_check_answer(rc, err, path);
    if (rc) {
        fuzz_require(!pts && n == 0, "a refused frame leaves nothing");
        return;
    }
    fuzz_require(n >= 1 && (want == 0 || n == want), "the count asked for");
    for (size_t i = 0; i < 3 * (size_t)n; i++) fuzz_require(isfinite(pts[i]), "finite points");
    free(pts);
}
