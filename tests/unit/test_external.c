/* The external method's parts without Python: its params (every refusal
 * naming the key), the process runner (exit status and output in the log,
 * a signal, a timeout that ends the whole process group, a command
 * ignoring SIGTERM killed after its grace, a stop request, a command that
 * cannot be found or run, a tcbench killed outright taking the command
 * with it, the stop signals tcbench blocks unblocked in the child, the
 * environment's additions), the log's tail in a message, the program a
 * step runs (a .py command's interpreter from params.python, else
 * $TCBENCH_PYTHON, else python3 from PATH; resolved to an absolute path that
 * every failure names), and the method refusing a transfer it was not told
 * about. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "methods/builtin.h"
#include "methods/external/external.h"
#include "methods/external/process.h"
#include "testutil.h"
#include "tcb/fsutil.h"
#include "tcb/progress.h"

static void expect_text(const char *msg, const char *text)
{
    if (!strstr(msg, text)) fail_msg("'%s' does not say '%s'", msg, text);
}

static void create_fails(const char *params, const char *text)
{
    void *self = NULL;
    tcb_error err = {0};
    assert_int_equal(tcb_method_external.create(params, &self, &err), TCB_ERR_INPUT);
    expect_text(err.msg, text);
}

static void test_params(void **state)
{
    (void)state;
    void *self;
    tcb_error err = {0};
    assert_int_equal(tcb_method_external.create("{\"command\": [\"python3\", \"m.py\"], \"timeout_s\": 2.5}", &self,
                                                &err), TCB_OK);
    const ext_method *m = self;
    assert_int_equal(m->n_command, 2);
    assert_string_equal(m->command[1], "m.py");
    assert_null(m->command[2]);
    assert_true(m->timeout_s == 2.5 && m->grace_s == 10);
    tcb_method_external.destroy(self);
    create_fails("{}", "external.params.command: required");
    create_fails("{\"command\": []}", "external.params.command: expected a list of 1 to 256 strings");
    create_fails("{\"command\": \"python3 m.py\"}", "external.params.command: expected a list");
    create_fails("{\"command\": [\"python3\", \"\"]}", "external.params.command[1]: expected a non-empty string");
    create_fails("{\"command\": [\"python3\", 3]}", "external.params.command[1]: expected a non-empty string");
    create_fails("{\"command\": [\"x\"], \"timeout_s\": -1}", "external.params.timeout_s: -1 is out of range");
    create_fails("{\"command\": [\"x\"], \"grace_s\": \"soon\"}", "external.params.grace_s: expected a number");
    create_fails("{\"command\": [\"x\"], \"timeout\": 5}", "external.params.timeout: unknown key");
    create_fails("{\"command\": [\"m.py\"], \"python\": \"\"}", "external.params.python: expected a non-empty string");
    create_fails("{\"command\": [\"m.py\"], \"python\": 3}", "external.params.python: expected a non-empty string");
    create_fails("{\"command\": [\"python3\", \"m.py\"], \"python\": \"/venv/bin/python\"}",
                 "external.params.python: runs .py commands, but command[0] 'python3' is not a .py script");
}

/* The method made from params, with $TCBENCH_PYTHON set to env (NULL: unset). */
static ext_method *create_with_env(const char *params, const char *env)
{
    void *self = NULL;
    tcb_error err = {0};
    if (env) setenv(EXT_PYTHON_ENV, env, 1);
    else unsetenv(EXT_PYTHON_ENV);
    int rc = tcb_method_external.create(params, &self, &err);
    unsetenv(EXT_PYTHON_ENV);
    if (rc) fail_msg("%s", err.msg);
    return self;
}

/* The step's argv, joined by spaces, in out[size]. */
static void joined_argv(const ext_method *m, char *out, size_t size)
{
    char **argv = NULL;
    tcb_error err = {0};
    assert_int_equal(ext_step_argv(m, "fit", "/w/manifest.json", &argv, &err), TCB_OK);
    out[0] = '\0';
    for (int k = 0; argv[k]; k++) snprintf(out + strlen(out), size - strlen(out), "%s%s", k ? " " : "", argv[k]);
    free(argv);
}

/* The interpreter of a .py command: params.python, else $TCBENCH_PYTHON, else
 * python3; a command naming its own program runs as listed. */
static void test_python_interpreter_precedence(void **state)
{
    (void)state;
    char text[512];
    ext_method *m = create_with_env("{\"command\": [\"m.py\", \"--x\"], \"python\": \"/p/python\"}", "/e/python");
    joined_argv(m, text, sizeof text);
    assert_string_equal(text, "/p/python m.py --x fit /w/manifest.json");
    assert_string_equal(m->python_from, "external.params.python");
    tcb_method_external.destroy(m);
    m = create_with_env("{\"command\": [\"m.py\"]}", "/e/python");
    joined_argv(m, text, sizeof text);
    assert_string_equal(text, "/e/python m.py fit /w/manifest.json");
    assert_string_equal(m->python_from, "TCBENCH_PYTHON");
    tcb_method_external.destroy(m);
    m = create_with_env("{\"command\": [\"m.py\"]}", NULL);
    joined_argv(m, text, sizeof text);
    assert_string_equal(text, "python3 m.py fit /w/manifest.json");
    assert_null(m->python_from);
    tcb_method_external.destroy(m);
    m = create_with_env("{\"command\": [\"python3\", \"m.py\"]}", "/e/python");
    joined_argv(m, text, sizeof text);
    assert_string_equal(text, "python3 m.py fit /w/manifest.json");
    tcb_method_external.destroy(m);
}

/* The program resolved as the log and the messages name it: absolute, with
 * where it came from; one that cannot be found names the key or variable. */
static void test_program_resolved_and_named(void **state)
{
    const char *dir = *state;
    char tool[TCB_PATH_MAX], path[TCB_PATH_MAX], want[2 * TCB_PATH_MAX], cwd[TCB_PATH_MAX];
    tu_write_text(dir, "py", "#!/bin/sh\n", tool, sizeof tool);
    chmod(tool, 0755);
    tcb_error err = {0};
    char params[2 * TCB_PATH_MAX];
    snprintf(params, sizeof params, "{\"command\": [\"m.py\"], \"python\": \"%s\"}", tool);
    ext_method *m = create_with_env(params, NULL);
    char *argv[] = {m->python, "m.py", NULL};
    assert_int_equal(ext_resolve_program(m, argv, path, &err), TCB_OK);
    assert_string_equal(path, tool);
    snprintf(want, sizeof want, "%s [external.params.python]", tool);
    assert_string_equal(m->program, want);
    /* Every failure after the run names it; an interrupt or no reconstructions do not. */
    tcb_fail(&err, TCB_ERR_INPUT, "pred/0.npy: not a .npy file");
    assert_int_equal(ext_name_program(m, TCB_ERR_INPUT, &err), TCB_ERR_INPUT);
    snprintf(want, sizeof want, "pred/0.npy: not a .npy file; program: %s [external.params.python]", tool);
    assert_string_equal(err.msg, want);
    tcb_fail(&err, TCB_ERR_UNSUPPORTED, "no reconstructions");
    assert_int_equal(ext_name_program(m, TCB_ERR_UNSUPPORTED, &err), TCB_ERR_UNSUPPORTED);
    assert_string_equal(err.msg, "no reconstructions");
    tcb_method_external.destroy(m);
    /* From PATH, a relative PATH entry included: absolute all the same. */
    assert_non_null(getcwd(cwd, sizeof cwd));
    char *old_path = getenv("PATH") ? strdup(getenv("PATH")) : NULL;
    assert_int_equal(chdir(dir), 0);
    setenv("PATH", ".", 1);
    m = create_with_env("{\"command\": [\"m.py\"]}", "py");
    char *by_name[] = {"py", "m.py", NULL};
    int rc = ext_resolve_program(m, by_name, path, &err);
    setenv("PATH", "/nonexistent-tcb", 1);
    int rc_missing = ext_resolve_program(m, by_name, want, &err);
    if (old_path) setenv("PATH", old_path, 1);
    free(old_path);
    assert_int_equal(chdir(cwd), 0);
    assert_int_equal(rc, TCB_OK);
    assert_string_equal(path, tool);
    snprintf(want, sizeof want, "%s [TCBENCH_PYTHON, py from PATH]", tool);
    assert_string_equal(m->program, want);
    assert_int_equal(rc_missing, TCB_ERR_INPUT);
    expect_text(err.msg, "TCBENCH_PYTHON (the interpreter of m.py): 'py': not found in PATH (/nonexistent-tcb)");
    tcb_method_external.destroy(m);
}

/* Runs `sh -c SCRIPT` with its output in dir/log. */
static int run_sh(const char *dir, const char *script, double timeout_s, double grace_s, ext_proc_result *r,
                  tcb_error *err)
{
    char log[TCB_PATH_MAX];
    snprintf(log, sizeof log, "%s/log", dir);
    char *argv[] = {"sh", "-c", (char *)script, NULL};
    ext_proc_spec s = {argv, NULL, log, timeout_s, grace_s, NULL, NULL, NULL};
    return ext_proc_run(&s, r, err);
}

static char *read_log(const char *dir)
{
    char path[TCB_PATH_MAX], *text;
    tcb_error err = {0};
    snprintf(path, sizeof path, "%s/log", dir);
    if (tcb_read_file(path, &text, NULL, &err)) fail_msg("%s", err.msg);
    return text;
}

static void test_exit_status_and_output(void **state)
{
    ext_proc_result r;
    tcb_error err = {0};
    assert_int_equal(run_sh(*state, "echo out; echo err >&2; read x; echo \"stdin [$x]\"; exit 7", 0, 1, &r, &err), TCB_OK);
    assert_int_equal(r.end, EXT_PROC_EXITED);
    assert_int_equal(r.status, 7);
    char *log = read_log(*state);
    assert_string_equal(log, "out\nerr\nstdin []\n"); /* stdin is /dev/null */
    free(log);
    assert_int_equal(run_sh(*state, "kill -KILL $$", 0, 1, &r, &err), TCB_OK);
    assert_int_equal(r.end, EXT_PROC_SIGNALED);
    assert_int_equal(r.status, SIGKILL);
}

/* pid has ended (gone, or a zombie nobody reaped yet), within 5 s. */
static int ended_soon(long pid)
{
    for (int k = 0; k < 500; k++) {
        char path[64], *stat;
        snprintf(path, sizeof path, "/proc/%ld/stat", pid);
        if (tcb_read_file(path, &stat, NULL, NULL)) return 1;
        int zombie = strstr(stat, ") Z") != NULL;
        free(stat);
        if (zombie) return 1;
        usleep(10000);
    }
    return 0;
}

/* The shell and its `sleep` (pid in dir/pid) are ended at the timeout. */
static void expect_group_stopped(const char *dir, const char *script, double grace_s)
{
    ext_proc_result r;
    tcb_error err = {0};
    double t0 = tcb_now_seconds();
    assert_int_equal(run_sh(dir, script, 1, grace_s, &r, &err), TCB_OK);
    assert_int_equal(r.end, EXT_PROC_TIMED_OUT);
    assert_true(tcb_now_seconds() - t0 < 6);
    char *log = read_log(dir);
    long sleeper = strtol(log, NULL, 10);
    free(log);
    assert_true(sleeper > 0);
    assert_true(ended_soon(sleeper));
}

static void test_timeout_ends_the_group(void **state)
{
    expect_group_stopped(*state, "sleep 30 & echo $!; wait", 10);
    /* Both ignore SIGTERM: SIGKILL after the grace, not after 30 s. */
    expect_group_stopped(*state, "trap '' TERM; sleep 30 & echo $!; wait; wait", 0.2);
}

/* A tcbench killed outright (here: a forked test process running the
 * command) leaves no command behind: the command gets SIGTERM (Linux). */
static void test_command_ends_with_tcbench(void **state)
{
#ifdef __linux__
    const char *dir = *state;
    char pidfile[TCB_PATH_MAX], script[3 * TCB_PATH_MAX + 64];
    snprintf(pidfile, sizeof pidfile, "%s/pid", dir);
    snprintf(script, sizeof script, "echo $$ > %s.tmp; mv %s.tmp %s; exec sleep 30", pidfile, pidfile, pidfile);
    pid_t runner = fork();
    assert_true(runner >= 0);
    if (runner == 0) {
        ext_proc_result r;
        _exit(run_sh(dir, script, 0, 1, &r, NULL) ? 1 : 0);
    }
    char *text = NULL;
    for (int k = 0; k < 1000 && tcb_read_file(pidfile, &text, NULL, NULL); k++) usleep(10000);
    assert_non_null(text);
    long command = strtol(text, NULL, 10);
    free(text);
    kill(runner, SIGKILL);
    waitpid(runner, NULL, 0);
    assert_true(ended_soon(command));
#else
    (void)state;
    skip();
#endif
}

static int stop_now(const void *arg)
{
    (void)arg;
    return 1;
}

static void test_stop_request(void **state)
{
    char log[TCB_PATH_MAX];
    snprintf(log, sizeof log, "%s/log", (const char *)*state);
    char *argv[] = {"sleep", "30", NULL};
    ext_proc_spec s = {argv, NULL, log, 0, 10, stop_now, NULL, NULL};
    ext_proc_result r;
    tcb_error err = {0};
    assert_int_equal(ext_proc_run(&s, &r, &err), TCB_OK);
    assert_int_equal(r.end, EXT_PROC_INTERRUPTED);
    assert_true(r.wall_s < 5);
}

static void run_fails(const char *dir, char *program, const char *text)
{
    char log[TCB_PATH_MAX];
    snprintf(log, sizeof log, "%s/log", dir);
    char *argv[] = {program, NULL};
    ext_proc_spec s = {argv, NULL, log, 0, 1, NULL, NULL, NULL};
    ext_proc_result r;
    tcb_error err = {0};
    assert_int_equal(ext_proc_run(&s, &r, &err), TCB_ERR_INPUT);
    expect_text(err.msg, text);
}

static void test_commands_that_cannot_run(void **state)
{
    const char *dir = *state;
    char plain[TCB_PATH_MAX], script[TCB_PATH_MAX];
    tu_write_text(dir, "plain", "echo hi\n", plain, sizeof plain);
    tu_write_text(dir, "script", "\x7f" "ELF not really\n", script, sizeof script);
    chmod(script, 0755);
    run_fails(dir, "tcb-no-such-command", "'tcb-no-such-command': not found in PATH");
    run_fails(dir, "/nonexistent/tcb-cmd", "'/nonexistent/tcb-cmd': no such executable file");
    run_fails(dir, plain, "not executable");
    run_fails(dir, script, "cannot run"); /* execve's own refusal, through the pipe */
    char path[TCB_PATH_MAX];
    tcb_error err = {0};
    assert_int_equal(ext_proc_resolve("sh", path, sizeof path, &err), TCB_OK);
    assert_true(path[0] == '/' && strstr(path, "/sh"));
}

/* tcbench blocks SIGTERM in every thread; the command must not inherit that. */
static void test_child_gets_default_signals(void **state)
{
    sigset_t term, old;
    sigemptyset(&term);
    sigaddset(&term, SIGTERM);
    pthread_sigmask(SIG_BLOCK, &term, &old);
    ext_proc_result r;
    tcb_error err = {0};
    int rc = run_sh(*state, "kill -TERM $$; sleep 5", 0, 1, &r, &err);
    pthread_sigmask(SIG_SETMASK, &old, NULL);
    assert_int_equal(rc, TCB_OK);
    assert_int_equal(r.end, EXT_PROC_SIGNALED);
    assert_int_equal(r.status, SIGTERM);
}

static void test_environment_additions(void **state)
{
    char log[TCB_PATH_MAX];
    snprintf(log, sizeof log, "%s/log", (const char *)*state);
    setenv("TCB_TEST_VAR", "parent", 1);
    setenv("TCB_TEST_KEPT", "kept", 1);
    char *argv[] = {"sh", "-c", "env | grep '^TCB_TEST_' | sort", NULL};
    char *set[] = {"TCB_TEST_VAR=child", "TCB_TEST_NEW=new", NULL};
    ext_proc_spec s = {argv, set, log, 0, 1, NULL, NULL, NULL};
    ext_proc_result r;
    tcb_error err = {0};
    assert_int_equal(ext_proc_run(&s, &r, &err), TCB_OK);
    char *text = read_log(*state);
    assert_string_equal(text, "TCB_TEST_KEPT=kept\nTCB_TEST_NEW=new\nTCB_TEST_VAR=child\n");
    free(text);
}

static void test_log_tail(void **state)
{
    char path[TCB_PATH_MAX], out[256];
    tu_write_text(*state, "log", "old 1\nold 2\n== header\nA\n\n  B\tb\nC \xc3\xa9\r\n\n", path, sizeof path);
    long from = (long)strlen("old 1\nold 2\n");
    ext_log_tail(path, from, 10, out, sizeof out);
    assert_string_equal(out, "== header | A |   B b | C ??"); /* blank lines skipped, non-ASCII as '?' */
    ext_log_tail(path, from, 2, out, sizeof out);
    assert_string_equal(out, "  B b | C ??");
    ext_log_tail(path, from, 10, out, 12); /* what fits of the latest lines */
    assert_string_equal(out, "C ??");
    ext_log_tail(path, (long)strlen("old 1\nold 2\n== header\nA\n\n  B\tb\nC \xc3\xa9\r\n\n"), 10, out, sizeof out);
    assert_string_equal(out, "");
}

static void test_transfer_needs_prepared_pairs(void **state)
{
    (void)state;
    void *self;
    tcb_error err = {0};
    assert_int_equal(tcb_method_external.create("{\"command\": [\"true\"]}", &self, &err), TCB_OK);
    tcb_sequence seq = {.n_verts = 1};
    float src[3] = {0}, out[3];
    assert_int_equal(tcb_method_external.transfer(self, &seq, 0, 1, src, 1, out, NULL, &err), TCB_ERR_INTERNAL);
    expect_text(err.msg, "external: pair 0->1 is not the one prepare_pairs announced next");
    tcb_method_external.destroy(self);
    assert_true(tcb_method_external.abi_version >= 4); /* prepare_pairs is read from 4 on */
    assert_non_null(tcb_method_external.prepare_pairs);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_params),
        cmocka_unit_test(test_python_interpreter_precedence),
        cmocka_unit_test_setup_teardown(test_program_resolved_and_named, tu_setup_tmpdir, tu_teardown_tmpdir),
        cmocka_unit_test_setup_teardown(test_exit_status_and_output, tu_setup_tmpdir, tu_teardown_tmpdir),
        cmocka_unit_test_setup_teardown(test_timeout_ends_the_group, tu_setup_tmpdir, tu_teardown_tmpdir),
        cmocka_unit_test_setup_teardown(test_stop_request, tu_setup_tmpdir, tu_teardown_tmpdir),
        cmocka_unit_test_setup_teardown(test_command_ends_with_tcbench, tu_setup_tmpdir, tu_teardown_tmpdir),
        cmocka_unit_test_setup_teardown(test_commands_that_cannot_run, tu_setup_tmpdir, tu_teardown_tmpdir),
        cmocka_unit_test_setup_teardown(test_child_gets_default_signals, tu_setup_tmpdir, tu_teardown_tmpdir),
        cmocka_unit_test_setup_teardown(test_environment_additions, tu_setup_tmpdir, tu_teardown_tmpdir),
        cmocka_unit_test_setup_teardown(test_log_tail, tu_setup_tmpdir, tu_teardown_tmpdir),
        cmocka_unit_test(test_transfer_needs_prepared_pairs),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
