/* tcbench — progress and log reporting.
 *
 * Methods and the runner report through a tcb_reporter (two callbacks and a
 * context), never by printing. The terminal implementation draws a bar on a
 * TTY, prints a plain line when a task starts and ends (and every 10 s in
 * between) when the output is not a TTY, and prints
 * nothing but warnings when quiet (CI=true or --quiet); debug lines only
 * when verbose. */
#ifndef TCB_PROGRESS_H
#define TCB_PROGRESS_H

#include <stdio.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef enum tcb_log_level { TCB_LOG_DEBUG, TCB_LOG_INFO, TCB_LOG_WARN } tcb_log_level;

typedef struct tcb_reporter {
    /* `done` of `total` units of the task named `label` are complete. */
    void (*progress)(void *ctx, double done, double total, const char *label);
    void (*log)(void *ctx, tcb_log_level level, const char *msg);
    void *ctx;
} tcb_reporter;

/* Null-safe helpers: a reporter with NULL callbacks is silent. */
void tcb_report_progress(const tcb_reporter *r, double done, double total,
                         const char *label);
void tcb_report_log(const tcb_reporter *r, tcb_log_level level, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

/* Terminal implementation. */
typedef struct tcb_term_progress {
    FILE *out;
    int is_tty;
    int quiet;
    int verbose;          /* also TCB_LOG_DEBUG lines (not when quiet) */
    double last_emit_s;   /* monotonic time of the last redraw / line */
    char label[128];
} tcb_term_progress;

/* quiet < 0: decide from the environment (CI set and non-empty → quiet). */
void tcb_term_progress_init(tcb_term_progress *tp, FILE *out, int quiet);
tcb_reporter tcb_term_progress_reporter(tcb_term_progress *tp);
/* End the current bar line (TTY) so the next output starts cleanly. */
void tcb_term_progress_finish(tcb_term_progress *tp);

/* Monotonic seconds, for timings. */
double tcb_now_seconds(void);

#ifdef __cplusplus
}
#endif
#endif
