/* Small helpers shared by the benchmark programs. */
#ifndef TCB_BENCH_UTIL_H
#define TCB_BENCH_UTIL_H

#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static inline double bench_now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

/* out ← the path of NAME in the directory of the source file `file` (pass
 * __FILE__: the absolute source path CMake compiles from, which spares bench
 * programs a configure-time define for their helper scripts). */
static inline void bench_sibling_path(char *out, size_t size, const char *file, const char *name)
{
    snprintf(out, size, "%s", file);
    char *slash = strrchr(out, '/');
    size_t dir = slash ? (size_t)(slash + 1 - out) : 0;
    snprintf(out + dir, size - dir, "%s", name);
}

/* Prints "<prog>: <message>" and exits 1. */
static inline void bench_die(const char *prog, const char *fmt, ...) __attribute__((format(printf, 2, 3), noreturn));

static inline void bench_die(const char *prog, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fprintf(stderr, "%s: ", prog);
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
    va_end(ap);
    exit(1);
}

/* A positive integer argument, or exit(2) with a message naming `what` and
 * where the usage is (atoi would turn "--help" into 0 repetitions). */
static inline int bench_positive_int(const char *s, const char *what, const char *usage_at)
{
    char *end;
    errno = 0;
    long v = strtol(s, &end, 10);
    if (!*s || *end || errno || v < 1 || v > 1000000000) {
        fprintf(stderr, "%s: expected a positive integer, got '%s' (usage: %s)\n", what, s, usage_at);
        exit(2);
    }
    return (int)v;
}

#endif
