#include "tcb/error.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

int tcb_fail(tcb_error *err, tcb_status code, const char *fmt, ...)
{
    if (err) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err->msg, sizeof err->msg, fmt, ap);
        va_end(ap);
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
