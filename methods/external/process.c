/* ext_proc_run (process.h): fork and execve, no shell, no posix_spawn.
 *
 * fork rather than posix_spawn for one thing posix_spawn cannot do: on
 * Linux the child asks for SIGTERM when tcbench dies (PR_SET_PDEATHSIG),
 * so a tcbench killed outright or by Ctrl-C (the command sits in its own
 * process group, out of the terminal's reach) does not leave a training
 * running unseen. (The request follows the thread that forked, which waits
 * for the command to its end.) Between fork and execve the child makes only
 * async-signal-safe calls (tcbench has other threads): the executable, the
 * environment and the file descriptors are all prepared by the parent.
 *
 * The child is waited for with waitid(WNOWAIT): it stays a zombie until the
 * end, so its pid, which is its process group's id, cannot be reused by an
 * unrelated process while the group is signalled. */
#include "methods/external/process.h"

#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>
#ifdef __linux__
#include <sys/prctl.h>
#endif

#include "tcb/fsutil.h"
#include "tcb/progress.h"

extern char **environ;

/* The wait's poll period: how late a timeout or a stop request is acted on. */
#define POLL_NS 10000000L

static int executable(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 && S_ISREG(st.st_mode) && access(path, X_OK) == 0;
}

/* path, made absolute against the current directory ("./" dropped). */
static int absolute(const char *path, char *out, size_t size, tcb_error *err)
{
    if (path[0] == '/') return tcb_path_join(out, size, err, "%s", path);
    char cwd[TCB_PATH_MAX];
    if (!getcwd(cwd, sizeof cwd)) return tcb_fail(err, TCB_ERR_IO, "cannot read the current directory: %s", strerror(errno));
    while (path[0] == '.' && path[1] == '/') path += 2;
    return tcb_path_join(out, size, err, "%s/%s", cwd, path);
}

int ext_proc_resolve(const char *name, char *out, size_t size, tcb_error *err)
{
    if (strchr(name, '/')) {
        if (executable(name)) return absolute(name, out, size, err);
        return tcb_fail(err, TCB_ERR_INPUT, "'%s': %s", name,
                        tcb_is_file(name) ? "not executable" : "no such executable file");
    }
    const char *path = getenv("PATH");
    if (!path) path = "/usr/local/bin:/usr/bin:/bin";
    for (const char *p = path;; p++) {
        size_t len = strcspn(p, ":");
        char cand[TCB_PATH_MAX];
        /* An empty entry is the current directory, as for execvp. */
        if ((size_t)snprintf(cand, sizeof cand, "%.*s%s%s", (int)len, p, len ? "/" : "", name) < sizeof cand &&
            executable(cand))
            return absolute(cand, out, size, err);
        p += len;
        if (!*p) break;
    }
    return tcb_fail(err, TCB_ERR_INPUT, "'%s': not found in PATH (%s)", name, path);
}

/* entry ("NAME=value") names a variable that one of set's entries sets. */
static int overridden(const char *entry, char *const *set)
{
    for (; set && *set; set++) {
        size_t len = strcspn(*set, "=");
        if (!strncmp(entry, *set, len) && entry[len] == '=') return 1;
    }
    return 0;
}

/* environ with set's entries replacing those of the same names; the
 * strings are borrowed, the array is malloc'ed (NULL: out of memory). */
static char **build_env(char *const *set)
{
    size_t n_env = 0, n_set = 0, n = 0;
    while (environ && environ[n_env]) n_env++;
    while (set && set[n_set]) n_set++;
    char **env = malloc((n_env + n_set + 1) * sizeof *env);
    if (!env) return NULL;
    for (size_t k = 0; k < n_env; k++)
        if (!overridden(environ[k], set)) env[n++] = environ[k];
    for (size_t k = 0; k < n_set; k++) env[n++] = set[k];
    env[n] = NULL;
    return env;
}

/* What the child needs, all made before fork. */
typedef struct child_setup {
    const char *path;
    char *const *argv;
    char *const *envp;
    int log_fd, null_fd, err_fd; /* err_fd: where a failed exec writes its errno */
    pid_t parent;
    struct sigaction dfl;        /* SIG_DFL */
} child_setup;

/* The child between fork and execve: async-signal-safe calls only. */
static void run_child(const child_setup *c)
{
    /* Its own group, so a timeout or a stop ends everything it started. */
    setpgid(0, 0);
#ifdef __linux__
    prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (getppid() != c->parent) _exit(127); /* tcbench died before the request took effect */
#endif
    /* tcbench blocks SIGTERM and SIGUSR1 in every thread (its stop
     * requests); a blocked mask and ignored signals survive execve. */
    static const int sigs[] = {SIGTERM, SIGUSR1, SIGINT, SIGHUP, SIGQUIT, SIGPIPE, SIGCHLD};
    for (size_t k = 0; k < sizeof sigs / sizeof sigs[0]; k++) sigaction(sigs[k], &c->dfl, NULL);
    sigset_t none;
    sigemptyset(&none);
    sigprocmask(SIG_SETMASK, &none, NULL);
    if (dup2(c->null_fd, 0) >= 0 && dup2(c->log_fd, 1) >= 0 && dup2(c->log_fd, 2) >= 0)
        execve(c->path, c->argv, c->envp);
    int e = errno;
    ssize_t ignored = write(c->err_fd, &e, sizeof e);
    (void)ignored;
    _exit(127);
}

/* The parent's side of the start: open the files, fork, and learn from the
 * close-on-exec pipe whether execve succeeded (EOF) or failed (its errno).
 * Once the pipe answers, the child has made itself a group leader. */
static int spawn(const ext_proc_spec *s, const char *path, char *const *envp, pid_t *pid, tcb_error *err)
{
    child_setup c = {.path = path, .argv = s->argv, .envp = envp, .parent = getpid()};
    c.dfl.sa_handler = SIG_DFL;
    sigemptyset(&c.dfl.sa_mask);
    int fds[2] = {-1, -1};
    c.log_fd = open(s->log_path, O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
    if (c.log_fd < 0) return tcb_fail(err, TCB_ERR_IO, "%s: cannot open the log: %s", s->log_path, strerror(errno));
    c.null_fd = open("/dev/null", O_RDONLY | O_CLOEXEC);
    int ok = c.null_fd >= 0 && pipe(fds) == 0 && fcntl(fds[0], F_SETFD, FD_CLOEXEC) == 0 &&
             fcntl(fds[1], F_SETFD, FD_CLOEXEC) == 0;
    c.err_fd = fds[1];
    *pid = ok ? fork() : -1;
    if (*pid == 0) run_child(&c);
    int fork_errno = errno;
    close(c.log_fd);
    if (c.null_fd >= 0) close(c.null_fd);
    if (fds[1] >= 0) close(fds[1]);
    int e = 0;
    ssize_t got = 0;
    if (*pid > 0)
        while ((got = read(fds[0], &e, sizeof e)) < 0 && errno == EINTR) continue;
    if (fds[0] >= 0) close(fds[0]);
    if (*pid < 0) return tcb_fail(err, TCB_ERR_IO, "'%s': cannot start: %s", s->argv[0], strerror(fork_errno));
    if (got != (ssize_t)sizeof e) return TCB_OK;
    while (waitpid(*pid, NULL, 0) < 0 && errno == EINTR) continue;
    return tcb_fail(err, TCB_ERR_INPUT, "'%s': cannot run %s: %s", s->argv[0], path, strerror(e));
}

/* The child has ended; it stays a zombie (WNOWAIT) until reaped. */
static int ended(pid_t pid)
{
    siginfo_t si;
    memset(&si, 0, sizeof si);
    while (waitid(P_PID, (id_t)pid, &si, WEXITED | WNOHANG | WNOWAIT) != 0)
        if (errno != EINTR) return 1; /* ECHILD: nothing left to wait for */
    return si.si_pid == pid;
}

static void nap(void)
{
    struct timespec ts = {0, POLL_NS};
    nanosleep(&ts, NULL);
}

/* SIGTERM to the group, and up to grace_s for the child to end. */
static void terminate(pid_t pid, double grace_s)
{
    kill(-pid, SIGTERM);
    double t0 = tcb_now_seconds();
    while (!ended(pid) && tcb_now_seconds() - t0 < grace_s) nap();
}

/* Waits for the end, the timeout or the stop request; *end says which. */
static void wait_child(const ext_proc_spec *s, pid_t pid, double t0, ext_proc_end *end)
{
    *end = EXT_PROC_EXITED;
    while (!ended(pid)) {
        if (s->interrupted && s->interrupted(s->interrupt_arg)) *end = EXT_PROC_INTERRUPTED;
        else if (s->timeout_s > 0 && tcb_now_seconds() - t0 >= s->timeout_s) *end = EXT_PROC_TIMED_OUT;
        if (*end != EXT_PROC_EXITED) {
            terminate(pid, s->grace_s);
            return;
        }
        nap();
    }
}

int ext_proc_run(const ext_proc_spec *s, ext_proc_result *r, tcb_error *err)
{
    char resolved[TCB_PATH_MAX];
    const char *path = s->path;
    int rc = path ? TCB_OK : ext_proc_resolve(s->argv[0], resolved, sizeof resolved, err);
    if (rc) return rc;
    if (!path) path = resolved;
    char **envp = build_env(s->env_set);
    if (!envp) return tcb_fail(err, TCB_ERR_NOMEM, "out of memory for the environment");
    double t0 = tcb_now_seconds();
    pid_t pid = -1;
    rc = spawn(s, path, envp, &pid, err);
    free(envp);
    if (rc) return rc;
    wait_child(s, pid, t0, &r->end);
    /* Whatever the command left in its group, or the command itself when
     * the grace ran out; the zombie keeps the group's id from reuse. */
    kill(-pid, SIGKILL);
    int status = 0;
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR) continue;
    r->wall_s = tcb_now_seconds() - t0;
    r->status = 0;
    if (r->end == EXT_PROC_EXITED && WIFSIGNALED(status)) r->end = EXT_PROC_SIGNALED, r->status = WTERMSIG(status);
    else if (r->end == EXT_PROC_EXITED) r->status = WEXITSTATUS(status);
    return TCB_OK;
}
