/* What the fuzz targets share: a scratch directory for the readers that
 * take a path, and the checks every reader's answer must pass.
 *
 * A target is a file of fuzz/targets/ defining LLVMFuzzerTestOneInput (and,
 * where it needs a setup done once, LLVMFuzzerInitialize). It is linked
 * twice: against libFuzzer in the fuzz build (cmake -DTCB_FUZZ=ON with
 * clang: coverage-guided search) and against replay_main.c in the test
 * build (any compiler: each committed seed and regression input is run
 * once, so a fixed crash stays fixed without clang). libFuzzer passes no
 * context, so a target keeps its setup (a sequence, a trainer) in
 * file-scope variables made once by LLVMFuzzerInitialize. */
#ifndef TCB_FUZZ_UTIL_H
#define TCB_FUZZ_UTIL_H

#include <stddef.h>
#include <stdint.h>

#include "tcb/error.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* Writes data[0..size) to `name` inside this process's scratch directory
 * (made on first use in $TMPDIR, else /dev/shm, else /tmp; removed at exit) and returns the file's path, valid
 * until the next call with the same name. Aborts when the disk refuses:
 * a target must never report a harness failure as a finding. */
const char *fuzz_file(const char *name, const uint8_t *data, size_t size);

/* fuzz_file with the last 8 bytes replaced by the FNV-1a 64 of the bytes
 * before them (tcb/hash.h), as the checkpoint formats end: random bytes
 * never match a checksum, which would stop the search at the first check,
 * so the checks behind it are what is searched (the checksum test itself
 * is a unit test). Inputs shorter than 8 bytes are written as they are. */
const char *fuzz_file_checksummed(const char *name, const uint8_t *data, size_t size);

/* The scratch directory itself. */
const char *fuzz_dir(void);

/* The contract of a reader's answer: rc is TCB_OK, or err holds rc and a
 * one-line message that names `path` (NULL: no path to name). Any breach
 * aborts, which libFuzzer reports as a crash with the input. With
 * TCB_FUZZ_VERBOSE set, each answer is printed (to see how deep a seed
 * gets). */
void fuzz_check_answer(int rc, const tcb_error *err, const char *path);

/* Aborts with the message when the condition fails: the invariants a
 * successful read must satisfy (indices in range, finite values). */
void fuzz_require(int cond, const char *what);

/* The answer of a reader of one frame of points (n of them, asked for
 * `want` when want > 0) checked: a refusal leaves nothing, an acceptance
 * is finite points, as many as asked for; frees pts. */
void fuzz_check_point_frame(int rc, const tcb_error *err, const char *path, float *pts, int n, int want);

#endif
