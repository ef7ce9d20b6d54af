#include "tcb/error.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

/* A message is one line of text: it is printed to terminals and logs and
 * stored in cell files, and it quotes what the user's file held (a JSON
 * key, a name), which may hold a newline or an escape sequence. ASCII
 * control characters are written as C escapes; the rest, UTF-8 included,
 * is kept. The result is truncated to the message's size. */
static void escape_controls(char *msg)
{
    char out[TCB_ERRMSG_MAX];
    size_t n = 0;
    for (const unsigned char *p = (const unsigned char *)msg; *p; p++) {
        char e[5] = {(char)*p, '\0'};
        if (*p == '\n' || *p == '\t' || *p == '\r')
            snprintf(e, sizeof e, "\\%c", *p == '\n' ? 'n' : *p == '\t' ? 't' : 'r');
        else if (*p < 0x20 || *p == 0x7f) snprintf(e, sizeof e, "\\x%02x", *p);
        size_t len = strlen(e);
        if (n + len >= sizeof out) break;
        memcpy(out + n, e, len);
        n += len;
    }
    out[n] = '\0';
    memcpy(msg, out, n + 1);
}

int tcb_fail(tcb_error *err, tcb_status code, const char *fmt, ...)
{
    if (err) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err->msg, sizeof err->msg, fmt, ap);
        va_end(ap);
        escape_controls(err->msg);
        err->code = code;
    }
    return (int)code;
}

void tcb_error_prefix(tcb_error *err, const char *fmt, ...)
{
    if (!err) return;
    char prefix[TCB_ERRMSG_MAX], old[TCB_ERRMSG_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(prefix, sizeof prefix, fmt, ap);
    va_end(ap);
    memcpy(old, err->msg, sizeof old);
    /* Truncating an over-long message is intended: keep the prefix whole. */
    size_t lp = strnlen(prefix, TCB_ERRMSG_MAX - 1);
    size_t lo = strnlen(old, TCB_ERRMSG_MAX - 1 - lp);
    memcpy(err->msg, prefix, lp);
    memcpy(err->msg + lp, old, lo);
    err->msg[lp + lo] = '\0';
    escape_controls(err->msg);
}

void tcb_error_clear(tcb_error *err)
{
    if (!err) return;
    err->code = TCB_OK;
    err->msg[0] = '\0';
}

const char *tcb_status_name(tcb_status code)
{
    switch (code) {
    case TCB_OK: return "ok";
    case TCB_ERR_INPUT: return "input";
    case TCB_ERR_IO: return "io";
    case TCB_ERR_NOMEM: return "nomem";
    case TCB_ERR_NUMERIC: return "numeric";
    case TCB_ERR_UNSUPPORTED: return "unsupported";
    case TCB_ERR_INTERNAL: return "internal";
    case TCB_ERR_INTERRUPTED: return "interrupted";
    }
    return "unknown";
}

int tcb_status_exit_code(tcb_status code)
{
    if (code == TCB_ERR_INTERRUPTED) return TCB_EXIT_INTERRUPTED;
    return code == TCB_ERR_INPUT || code == TCB_ERR_IO ? 2 : 1;
}
