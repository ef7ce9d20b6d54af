/* Private to datasets/: a growing string, for the cache keys that describe
 * a sequence's source files (cache.c and the readers). */
#ifndef TCB_DATASETS_STRBUF_H
#define TCB_DATASETS_STRBUF_H

#include <stddef.h>

typedef struct tcb_strbuf {
    char *s; /* NUL-terminated once anything is appended; free() it */
    size_t len, cap;
} tcb_strbuf;

/* Appends printf-style; −1 when out of memory (the text so far is kept). */
int tcb_sb_printf(tcb_strbuf *b, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

#endif
