#include "tcb/progress.h"

#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

double tcb_now_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

void tcb_report_progress(const tcb_reporter *r, double done, double total, const char *label)
{
    if (r && r->progress) r->progress(r->ctx, done, total, label);
}

void tcb_report_log(const tcb_reporter *r, tcb_log_level level, const char *fmt, ...)
{
    if (!r || !r->log) return;
    char msg[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    r->log(r->ctx, level, msg);
}

/* ---- terminal implementation ------------------------------------------ */

#define BAR_WIDTH 30
#define TTY_REDRAW_S 0.1 /* at most 10 redraws a second */
#define PLAIN_EVERY_S 10.0

static void draw_bar(tcb_term_progress *tp, double done, double total)
{
    double frac = total > 0 ? done / total : 0;
    if (frac < 0) frac = 0;
    if (frac > 1) frac = 1;
    int filled = (int)(frac * BAR_WIDTH + 0.5);
    char bar[BAR_WIDTH + 1];
    for (int k = 0; k < BAR_WIDTH; k++) bar[k] = k < filled ? '#' : '.';
    bar[BAR_WIDTH] = '\0';
    /* \r + clear-to-end-of-line: redraw in place. */
    fprintf(tp->out, "\r\033[K%-48.48s [%s] %5.1f%% (%.0f/%.0f)", tp->label, bar, 100 * frac, done, total);
    fflush(tp->out);
}

static void term_progress(void *ctx, double done, double total, const char *label)
{
    tcb_term_progress *tp = ctx;
    if (tp->quiet) return;
    int new_label = strncmp(tp->label, label ? label : "", sizeof tp->label - 1) != 0;
    if (new_label) {
        snprintf(tp->label, sizeof tp->label, "%s", label ? label : "");
    }
    double now = tcb_now_seconds();
    int finished = done >= total;
    if (tp->is_tty) {
        if (new_label || finished || now - tp->last_emit_s >= TTY_REDRAW_S) {
            draw_bar(tp, done, total);
            tp->last_emit_s = now;
        }
        return;
    }
    /* Not a terminal (a log file): a line when a task starts, when it ends,
     * and at most every PLAIN_EVERY_S in between. */
    if (new_label || finished || now - tp->last_emit_s >= PLAIN_EVERY_S) {
        fprintf(tp->out, "%s: %.0f%% (%.0f/%.0f)\n", tp->label, total > 0 ? 100 * done / total : 100.0, done,
                total);
        fflush(tp->out);
        tp->last_emit_s = now;
    }
}

static void term_log(void *ctx, tcb_log_level level, const char *msg)
{
    tcb_term_progress *tp = ctx;
    if ((level == TCB_LOG_DEBUG && !tp->verbose) || (tp->quiet && level < TCB_LOG_WARN)) return;
    if (tp->is_tty) fputs("\r\033[K", tp->out);
    fprintf(tp->out, "%s%s\n", level == TCB_LOG_WARN ? "warning: " : "", msg);
    fflush(tp->out);
    tp->label[0] = '\0'; /* the bar line was overwritten: redraw on the next update */
}

void tcb_term_progress_init(tcb_term_progress *tp, FILE *out, int quiet)
{
    memset(tp, 0, sizeof *tp);
    tp->out = out;
    tp->is_tty = isatty(fileno(out));
    if (quiet < 0) {
        const char *ci = getenv("CI");
        quiet = ci && *ci && strcmp(ci, "0") != 0 && strcmp(ci, "false") != 0;
    }
    tp->quiet = quiet;
}

tcb_reporter tcb_term_progress_reporter(tcb_term_progress *tp)
{
    tcb_reporter r = {term_progress, term_log, tp};
    return r;
}

void tcb_term_progress_finish(tcb_term_progress *tp)
{
    if (tp->is_tty && !tp->quiet && tp->label[0]) fputc('\n', tp->out);
    tp->label[0] = '\0';
}
