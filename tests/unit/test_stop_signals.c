/* cli/stop_signals.c: SIGTERM and SIGUSR1 as a stop request. Each case runs
 * in a child process, since what is tested is whether a signal kills the
 * process: the parent reads how the child ended. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <signal.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "cli/stop_signals.h"

enum { CHILD_STOPPED = 75, CHILD_NO_REQUEST = 3, CHILD_WRONG_SIGNAL = 4 };

/* Polls the request for up to 10 s: the watching thread sets it. */
static int wait_for_request(tcb_stop_signals *s)
{
    const struct timespec tick = {0, 1000000};
    for (int k = 0; k < 10000 && !tcb_stop_signals_requested(s); k++) nanosleep(&tick, NULL);
    return tcb_stop_signals_requested(s);
}

static int run_child(void (*child)(void))
{
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) child();
    int status = 0;
    assert_int_equal(waitpid(pid, &status, 0), pid);
    return status;
}

/* A stop, its twin during the run, and two more after end (Slurm's scancel
 * signals the step and the batch shell passes its own on, late): the
 * process lives to exit 75. */
static void stop_then_late_signals(void)
{
    tcb_stop_signals s;
    if (tcb_stop_signals_start(&s)) _exit(1);
    kill(getpid(), SIGTERM);
    int sig = wait_for_request(&s);
    if (!sig) _exit(CHILD_NO_REQUEST);
    if (sig != SIGTERM) _exit(CHILD_WRONG_SIGNAL);
    kill(getpid(), SIGUSR1);
    tcb_stop_signals_end(&s);
    kill(getpid(), SIGUSR1);
    kill(getpid(), SIGTERM);
    _exit(CHILD_STOPPED);
}

static void test_late_signal_after_a_stop(void **state)
{
    (void)state;
    int status = run_child(stop_then_late_signals);
    assert_true(WIFEXITED(status));
    assert_int_equal(WEXITSTATUS(status), CHILD_STOPPED);
}

/* No stop during the run: after end, SIGTERM does what it does by default. */
static void no_stop_then_term(void)
{
    tcb_stop_signals s;
    if (tcb_stop_signals_start(&s)) _exit(1);
    tcb_stop_signals_end(&s);
    kill(getpid(), SIGTERM);
    _exit(0);
}

static void test_default_restored_without_a_stop(void **state)
{
    (void)state;
    int status = run_child(no_stop_then_term);
    assert_true(WIFSIGNALED(status));
    assert_int_equal(WTERMSIG(status), SIGTERM);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_late_signal_after_a_stop),
                                       cmocka_unit_test(test_default_restored_without_a_stop)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
