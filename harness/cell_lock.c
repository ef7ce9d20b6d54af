/* Cell locks: any number of tcbench processes, on any number of machines
 * sharing one run directory, compute each cell once.
 *
 * A lock is the file <cell>.json.lock holding {"host", "pid", "started"};
 * its modification time is the heartbeat, refreshed by a thread of the
 * holder every timeout/4. It is created by link(2) of a complete temporary
 * file, which is atomic and exclusive on local file systems and on NFS
 * (O_EXCL was not on NFSv2, and flock does not cross machines). A lock
 * whose heartbeat is older than the timeout, or whose process is gone on
 * this host, is taken over; the taker first claims <lock>.takeover the same
 * way, so two processes finding one stale lock cannot both take it. */
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <pthread.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "harness/harness_internal.h"
#include "tcb/fsutil.h"
#include "tcb/json.h"

#define TAKEOVER_STALE_S 60.0 /* a taker that died mid-takeover */

static void progress_path(char *out, size_t size, const char *lock)
{
    snprintf(out, size, "%s.progress", lock);
}

/* Removes <lock>.progress and a killed writer's temporaries of it: the
 * previous holder's progress is not the new holder's. */
static void clear_progress(const char *lock)
{
    char path[TCB_PATH_MAX + 16];
    progress_path(path, sizeof path, lock);
    unlink(path);
    tcb_remove_stale_temps_of(path);
}

/* Writes the lock's latest progress, if new, into <lock>.progress; called
 * with l->mu held, which it drops while writing. */
static void write_progress(tcb_cell_lock *l)
{
    if (!l->progress_new) return;
    char text[sizeof l->progress + 1], path[TCB_PATH_MAX + 16];
    int n = snprintf(text, sizeof text, "%s\n", l->progress);
    l->progress_new = 0;
    pthread_mutex_unlock(&l->mu);
    progress_path(path, sizeof path, l->path);
    tcb_error err = {0};
    (void)tcb_write_file_atomic(path, text, (size_t)n, &err); /* a status nicety: never fails the cell */
    pthread_mutex_lock(&l->mu);
}

static void *heartbeat(void *arg)
{
    tcb_cell_lock *l = arg;
    pthread_mutex_lock(&l->mu);
    while (!l->stop) {
        struct timespec until;
        clock_gettime(CLOCK_REALTIME, &until);
        double period = l->timeout_s / 4 < 1 ? 1 : l->timeout_s / 4;
        until.tv_sec += (time_t)period;
        pthread_cond_timedwait(&l->cv, &l->mu, &until);
        if (l->stop) break;
        utimensat(AT_FDCWD, l->path, NULL, 0);
        write_progress(l);
    }
    pthread_mutex_unlock(&l->mu);
    return NULL;
}

static void note_progress(tcb_cell_lock *l, double done, double total, const char *label)
{
    if (!l->beating) return;
    pthread_mutex_lock(&l->mu);
    if (total > 0)
        snprintf(l->progress, sizeof l->progress, "%s %.0f/%.0f (%.0f %%)", label ? label : "", done, total,
                 100.0 * done / total);
    else
        snprintf(l->progress, sizeof l->progress, "%s", label ? label : "");
    l->progress_new = 1;
    pthread_mutex_unlock(&l->mu);
}

static void lock_reporter_progress(void *ctx, double done, double total, const char *label)
{
    tcb_lock_reporter *r = ctx;
    note_progress(r->lock, done, total, label);
    tcb_report_progress(&r->inner, done, total, label);
}

static void lock_reporter_log(void *ctx, tcb_log_level level, const char *msg)
{
    tcb_lock_reporter *r = ctx;
    if (r->inner.log) r->inner.log(r->inner.ctx, level, msg);
}

tcb_reporter tcb_lock_reporter_make(tcb_lock_reporter *storage, tcb_cell_lock *lock, const tcb_reporter *inner)
{
    storage->lock = lock;
    storage->inner = *inner;
    return (tcb_reporter){lock_reporter_progress, lock_reporter_log, storage};
}

/* The holder's progress note beside the lock at `path`, into info. */
static void read_progress(const char *path, tcb_lock_info *info)
{
    char ppath[TCB_PATH_MAX + 16], *text;
    tcb_error err = {0};
    progress_path(ppath, sizeof ppath, path);
    if (tcb_read_file(ppath, &text, NULL, &err)) return;
    snprintf(info->progress, sizeof info->progress, "%s", text);
    info->progress[strcspn(info->progress, "\n")] = '\0';
    free(text);
}

/* The lock file at `path`: 0, or -1 when there is none. */
static int read_lock(const char *path, tcb_lock_info *info)
{
    memset(info, 0, sizeof *info);
    struct stat st;
    char *text;
    tcb_error err = {0};
    if (stat(path, &st) || tcb_read_file(path, &text, NULL, &err)) return -1;
    cJSON *j = cJSON_Parse(text);
    free(text);
    const cJSON *host = cJSON_GetObjectItemCaseSensitive(j, "host");
    const cJSON *pid = cJSON_GetObjectItemCaseSensitive(j, "pid");
    const cJSON *started = cJSON_GetObjectItemCaseSensitive(j, "started");
    /* A pid outside pid_t's range is no pid (and casting it would be undefined). */
    int ok = cJSON_IsString(host) && cJSON_IsNumber(pid) && pid->valuedouble >= 1 &&
             pid->valuedouble <= INT_MAX && cJSON_IsNumber(started);
    if (ok) {
        snprintf(info->host, sizeof info->host, "%s", host->valuestring);
        info->pid = (long)pid->valuedouble, info->started = started->valuedouble;
    }
    cJSON_Delete(j);
    struct timespec now;
    clock_gettime(CLOCK_REALTIME, &now);
    info->heartbeat_age_s = (double)(now.tv_sec - st.st_mtim.tv_sec) + (now.tv_nsec - st.st_mtim.tv_nsec) * 1e-9;
    info->valid = ok;
    read_progress(path, info);
    return 0;
}

/* An unreadable lock counts until its heartbeat is old: it may be in the
 * middle of being written by a takeover. */
const char *tcb_cell_lock_stale_reason(const tcb_lock_info *h, double timeout_s)
{
    char me[256] = "";
    gethostname(me, sizeof me - 1);
    if (h->heartbeat_age_s > timeout_s) return "its heartbeat stopped";
    if (h->valid && !strcmp(h->host, me) && h->pid > 0 && kill((pid_t)h->pid, 0) && errno == ESRCH)
        return "its process is gone";
    return NULL;
}

static int lock_path(char *out, size_t size, const char *cell_path, tcb_error *err)
{
    return tcb_path_join(out, size, err, "%s.lock", cell_path);
}

int tcb_cell_lock_holder(const char *cell_path, tcb_lock_info *info)
{
    char path[TCB_PATH_MAX];
    tcb_error err = {0};
    return lock_path(path, sizeof path, cell_path, &err) ? -1 : read_lock(path, info);
}

static int write_lock_temp(const char *path, char *tmp, size_t size, tcb_error *err)
{
    char host[256] = "";
    gethostname(host, sizeof host - 1);
    struct timespec now;
    clock_gettime(CLOCK_REALTIME, &now);
    char text[512];
    int n = snprintf(text, sizeof text, "{\"host\": \"%s\", \"pid\": %ld, \"started\": %.3f}\n", host, (long)getpid(),
                     (double)now.tv_sec + now.tv_nsec * 1e-9);
    int rc = tcb_temp_path_for(path, tmp, size, err);
    if (!rc) {
        FILE *f = fopen(tmp, "wb");
        int written = f && fwrite(text, 1, (size_t)n, f) == (size_t)n;
        if (f && fclose(f)) written = 0;
        /* A full disk must not leave a temporary that no cleanup knows. */
        if (!written) rc = tcb_fail(err, TCB_ERR_IO, "%s: cannot write: %s", tmp, strerror(errno)), unlink(tmp);
    }
    return rc;
}

/* Takes over the stale lock `path` holding `old`: 1 taken, 0 somebody else
 * is at it or the lock changed meanwhile. */
static int take_over(const char *path, const char *tmp, const tcb_lock_info *old)
{
    char guard[TCB_PATH_MAX + 16];
    snprintf(guard, sizeof guard, "%s.takeover", path);
    if (link(tmp, guard)) {
        struct stat st;
        if (errno != EEXIST || stat(guard, &st) || difftime(time(NULL), st.st_mtime) < TAKEOVER_STALE_S) return 0;
        unlink(guard); /* its taker died: the next attempt retries */
        return 0;
    }
    tcb_lock_info now;
    int same = !read_lock(path, &now) && now.pid == old->pid && now.started == old->started &&
               !strcmp(now.host, old->host);
    /* rename replaces the dead holder's file in one step: an unlink and a
     * link would leave a moment without a lock, in which another process
     * would claim it as free and this takeover would fail unsaid. */
    int taken = same && !rename(tmp, path);
    unlink(guard);
    return taken;
}

int tcb_cell_lock_acquire(tcb_cell_lock *l, const char *cell_path, double timeout_s, tcb_lock_info *holder,
                          char *note, size_t note_size, tcb_error *err)
{
    memset(l, 0, sizeof *l);
    memset(holder, 0, sizeof *holder);
    note[0] = '\0';
    l->timeout_s = timeout_s;
    char tmp[TCB_PATH_MAX];
    int rc = lock_path(l->path, sizeof l->path, cell_path, err);
    if (!rc) rc = write_lock_temp(l->path, tmp, sizeof tmp, err);
    if (rc) return rc;
    int claimed = !link(tmp, l->path);
    if (!claimed && errno != EEXIST) {
        rc = tcb_fail(err, TCB_ERR_IO, "%s: cannot create the lock: %s", l->path, strerror(errno));
    } else if (!claimed && !read_lock(l->path, holder)) {
        const char *why = tcb_cell_lock_stale_reason(holder, timeout_s);
        if (why && (claimed = take_over(l->path, tmp, holder)))
            snprintf(note, note_size, "took over the lock of %s pid %ld: %s (heartbeat %.0f s old)", holder->host,
                     holder->pid, why, holder->heartbeat_age_s);
    } else if (!claimed) {
        claimed = !link(tmp, l->path); /* released between our link and our read */
    }
    unlink(tmp);
    if (rc || !claimed) return rc;
    l->held = 1;
    /* A claimant killed between its temporary and the link left that
     * temporary; a live one's keeps its pid and stays. */
    tcb_remove_stale_temps_of(l->path);
    clear_progress(l->path);
    pthread_mutex_init(&l->mu, NULL);
    pthread_cond_init(&l->cv, NULL);
    if (pthread_create(&l->thread, NULL, heartbeat, l)) {
        tcb_cell_lock_release(l);
        return tcb_fail(err, TCB_ERR_INTERNAL, "%s: cannot start the heartbeat", l->path);
    }
    l->beating = 1;
    return TCB_OK;
}

void tcb_cell_lock_release(tcb_cell_lock *l)
{
    if (!l->held) return;
    if (l->beating) {
        pthread_mutex_lock(&l->mu);
        l->stop = 1;
        pthread_cond_signal(&l->cv);
        pthread_mutex_unlock(&l->mu);
        pthread_join(l->thread, NULL);
    }
    pthread_cond_destroy(&l->cv);
    pthread_mutex_destroy(&l->mu);
    clear_progress(l->path);
    unlink(l->path);
    l->held = l->beating = 0;
}
