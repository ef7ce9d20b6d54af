/* The last lines of the command's log, for a failed cell's message. */
#include "methods/external/external.h"

#include <stdio.h>
#include <string.h>

/* The part of the log read: a traceback's end is in its last few KiB. */
#define TAIL_BYTES 8192
/* A line's share of the message: longer lines keep their start. */
#define LINE_MAX_CHARS 200

/* Printable ASCII only: the message goes into JSON cell files and terminal
 * tables, where control characters and bytes of a UTF-8 sequence the cut
 * went through would break them. */
static void sanitize(char *s)
{
    for (; *s; s++)
        if (*s < 0x20 || *s > 0x7e) *s = (*s == '\t') ? ' ' : '?';
}

/* The last non-blank line of buf ending at or before `before`, as
 * [*start, *end); 0 when there is none. */
static int line_before(const char *buf, const char *before, const char **start, const char **end)
{
    const char *p = before;
    while (p > buf && (p[-1] == '\n' || p[-1] == '\r' || p[-1] == ' ')) p--;
    if (p == buf) return 0;
    *end = p;
    while (p > buf && p[-1] != '\n') p--;
    *start = p;
    return 1;
}

void ext_log_tail(const char *path, long from, int max_lines, char *out, size_t size)
{
    out[0] = '\0';
    FILE *f = fopen(path, "rb");
    if (!f) return;
    char buf[TAIL_BYTES + 1];
    long end = fseek(f, 0, SEEK_END) == 0 ? ftell(f) : -1;
    long at = end - TAIL_BYTES > from ? end - TAIL_BYTES : from;
    size_t n = end >= 0 && at <= end && fseek(f, at, SEEK_SET) == 0 ? fread(buf, 1, (size_t)(end - at), f) : 0;
    fclose(f);
    buf[n] = '\0';
    for (size_t k = 0; k < n; k++)
        if (!buf[k]) buf[k] = ' '; /* a NUL byte would end the text early */
    /* Lines from the last backwards, each placed before the ones kept, while they fit. */
    char joined[TAIL_BYTES + 64];
    size_t used = 0, cap = size - 1 < sizeof joined ? size - 1 : sizeof joined - 1;
    const char *before = buf + n, *s, *e;
    for (int k = 0; k < max_lines && line_before(buf, before, &s, &e); k++, before = s) {
        size_t len = (size_t)(e - s) > LINE_MAX_CHARS ? LINE_MAX_CHARS : (size_t)(e - s);
        size_t add = len + (used ? 3 : 0);
        if (used + add > cap) break;
        memmove(joined + add, joined, used);
        memcpy(joined, s, len);
        if (used) memcpy(joined + len, " | ", 3);
        used += add;
    }
    joined[used] = '\0';
    sanitize(joined);
    memcpy(out, joined, used + 1);
}
