/* SIGTERM and SIGUSR1 as a request to stop cleanly (cli/stop_signals.c),
 * for `tcbench run`. */
#ifndef TCB_CLI_STOP_SIGNALS_H
#define TCB_CLI_STOP_SIGNALS_H

#include <pthread.h>
#include <signal.h>
#include <stdatomic.h>

/* SIGTERM / SIGUSR1 as a stop request (cli/stop_signals.c): start
 * blocks them in the calling thread (call it before any other thread
 * exists) and starts the thread that waits for them; requested() is the
 * signal received, 0 before one (a tcb_run_opts.interrupted); end restores
 * the mask, and once a stop was requested (or one is pending) leaves
 * SIGTERM and SIGUSR1 ignored, so that a late second one cannot kill the
 * process on its way out. */
typedef struct tcb_stop_signals {
    sigset_t set, old;
    pthread_t thread;
    int started;
    atomic_int signal, closing;
} tcb_stop_signals;
int tcb_stop_signals_start(tcb_stop_signals *s);
int tcb_stop_signals_requested(const void *s);
void tcb_stop_signals_end(tcb_stop_signals *s);

#endif
