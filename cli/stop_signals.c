/* SIGTERM and SIGUSR1 as a request to stop cleanly (Slurm sends SIGTERM
 * before it preempts or cancels a job, and `--signal=USR1@120` ahead of the
 * time limit): the signals are blocked in every thread and one thread waits
 * for them with sigwait, so the request is an ordinary atomic flag the run
 * polls at its safe points, and no handler runs in the middle of a
 * training step. */
#include <pthread.h>
#include <signal.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "cli/stop_signals.h"

static void *wait_for_signal(void *arg)
{
    tcb_stop_signals *s = arg;
    for (;;) {
        int sig = 0;
        if (sigwait(&s->set, &sig)) continue;
        if (atomic_load(&s->closing)) return NULL;
        /* Said once: a stop often comes twice (Slurm's scancel signals the
         * job step and the batch shell, which passes its own on). */
        if (!atomic_exchange(&s->signal, sig))
            fprintf(stderr, "tcbench: %s received: stopping at the next safe point and saving the state\n",
                    sig == SIGTERM ? "SIGTERM" : "SIGUSR1");
    }
}

int tcb_stop_signals_start(tcb_stop_signals *s)
{
    memset(s, 0, sizeof *s);
    sigemptyset(&s->set);
    sigaddset(&s->set, SIGTERM);
    sigaddset(&s->set, SIGUSR1);
    /* Threads created later (OpenMP's, the lock heartbeats) inherit the mask. */
    if (pthread_sigmask(SIG_BLOCK, &s->set, &s->old)) return -1;
    if (pthread_create(&s->thread, NULL, wait_for_signal, s)) {
        pthread_sigmask(SIG_SETMASK, &s->old, NULL);
        return -1;
    }
    s->started = 1;
    return 0;
}

int tcb_stop_signals_requested(const void *arg)
{
    const tcb_stop_signals *s = arg;
    return atomic_load(&((tcb_stop_signals *)s)->signal);
}

/* A stop often comes twice, and the second can arrive after the run has
 * ended: unblocked with its default action it would kill the process before
 * it reports the saved state and exits 75 (a cancelled Slurm task died so of
 * its batch shell's USR1). So what is pending counts as a request too, and
 * once a stop was requested the signals stay ignored: the process is
 * stopping already. Without one, they act as before the run. */
void tcb_stop_signals_end(tcb_stop_signals *s)
{
    if (!s->started) return;
    atomic_store(&s->closing, 1);
    pthread_kill(s->thread, SIGUSR1);
    pthread_join(s->thread, NULL);
    const struct timespec now = {0, 0};
    for (int sig; (sig = sigtimedwait(&s->set, NULL, &now)) > 0;) {
        int none = 0;
        atomic_compare_exchange_strong(&s->signal, &none, sig);
    }
    if (atomic_load(&s->signal)) {
        struct sigaction ignore = {.sa_handler = SIG_IGN};
        sigaction(SIGTERM, &ignore, NULL);
        sigaction(SIGUSR1, &ignore, NULL);
    }
    pthread_sigmask(SIG_SETMASK, &s->old, NULL);
    s->started = 0;
}
