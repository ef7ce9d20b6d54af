#include "tcb/fsutil.h"

#include <dirent.h>
#include <errno.h>
#include <signal.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

int tcb_path_join(char *out, size_t size, tcb_error *err, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(out, size, fmt, ap);
    va_end(ap);
    if (n < 0 || (size_t)n >= size)
        return tcb_fail(err, TCB_ERR_INPUT, "path too long (%d bytes, limit %zu)", n, size - 1);
    return TCB_OK;
}

int tcb_is_dir(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 && S_ISDIR(st.st_mode);
}

int tcb_is_file(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 && S_ISREG(st.st_mode);
}

int tcb_mkdirs(const char *path, tcb_error *err)
{
    char buf[TCB_PATH_MAX];
    if (tcb_path_join(buf, sizeof buf, err, "%s", path)) return err ? err->code : TCB_ERR_INPUT;
    size_t len = strlen(buf);
    for (size_t i = 1; i <= len; i++) {
        if (buf[i] != '/' && buf[i] != '\0') continue;
        char saved = buf[i];
        buf[i] = '\0';
        if (mkdir(buf, 0777) != 0 && errno != EEXIST)
            return tcb_fail(err, TCB_ERR_IO, "%s: cannot create directory: %s", buf, strerror(errno));
        if (!tcb_is_dir(buf))
            return tcb_fail(err, TCB_ERR_IO, "%s: exists and is not a directory", buf);
        buf[i] = saved;
    }
    return TCB_OK;
}

int tcb_empty_dir(const char *dir, tcb_error *err)
{
    DIR *d = opendir(dir);
    if (!d) return errno == ENOENT ? TCB_OK : tcb_fail(err, TCB_ERR_IO, "%s: cannot list: %s", dir, strerror(errno));
    int rc = TCB_OK;
    for (struct dirent *e; !rc && (e = readdir(d));) {
        char path[TCB_PATH_MAX];
        struct stat st;
        if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, "..")) continue;
        rc = tcb_path_join(path, sizeof path, err, "%s/%s", dir, e->d_name);
        if (rc) break;
        int is_dir = lstat(path, &st) == 0 && S_ISDIR(st.st_mode); /* lstat: a link to a directory is a link */
        if (is_dir) rc = tcb_empty_dir(path, err);
        if (!rc && (is_dir ? rmdir(path) : unlink(path)) != 0 && errno != ENOENT)
            rc = tcb_fail(err, TCB_ERR_IO, "%s: cannot remove: %s", path, strerror(errno));
    }
    closedir(d);
    return rc;
}

/* mkdir -p of the directory part of `path`. */
static int make_parent(const char *path, tcb_error *err)
{
    char dir[TCB_PATH_MAX];
    if (tcb_path_join(dir, sizeof dir, err, "%s", path)) return err ? err->code : TCB_ERR_INPUT;
    char *slash = strrchr(dir, '/');
    if (!slash || slash == dir) return TCB_OK;
    *slash = '\0';
    return tcb_mkdirs(dir, err);
}

int tcb_temp_path_for(const char *path, char *tmp, size_t tmp_size, tcb_error *err)
{
    int rc = make_parent(path, err);
    if (rc) return rc;
    /* The writer's pid in the name tells a killed writer's debris from the
     * temporary of a live concurrent writer (tcb_remove_stale_temps). */
    if (tcb_path_join(tmp, tmp_size, err, "%s.tmp-%ld-XXXXXX", path, (long)getpid())) return TCB_ERR_INPUT;
    int fd = mkstemp(tmp);
    if (fd < 0) return tcb_fail(err, TCB_ERR_IO, "%s: cannot create temporary file: %s", tmp, strerror(errno));
    /* mkstemp creates 0600; results, reports and caches are meant to be shared. */
    fchmod(fd, 0644);
    close(fd);
    return TCB_OK;
}

int tcb_publish(const char *tmp, const char *path, tcb_error *err)
{
    if (rename(tmp, path) != 0) {
        int e = errno;
        unlink(tmp);
        return tcb_fail(err, TCB_ERR_IO, "%s: cannot rename into place: %s", path, strerror(e));
    }
    return TCB_OK;
}

int tcb_atomic_open(tcb_atomic_file *af, const char *path, tcb_error *err)
{
    memset(af, 0, sizeof *af);
    if (tcb_path_join(af->path, sizeof af->path, err, "%s", path)) return TCB_ERR_INPUT;
    int rc = tcb_temp_path_for(path, af->tmp, sizeof af->tmp, err);
    if (rc) return rc;
    af->fp = fopen(af->tmp, "wb");
    if (!af->fp) {
        int e = errno;
        unlink(af->tmp);
        return tcb_fail(err, TCB_ERR_IO, "%s: cannot open for writing: %s", af->tmp, strerror(e));
    }
    return TCB_OK;
}

int tcb_atomic_commit(tcb_atomic_file *af, tcb_error *err)
{
    /* fsync before rename: a crash must leave either the old file or the
     * complete new one, never an empty file under the final name. */
    int bad = ferror(af->fp) || fflush(af->fp) != 0 || fsync(fileno(af->fp)) != 0;
    int e = errno;
    bad |= fclose(af->fp) != 0;
    af->fp = NULL;
    if (bad) {
        unlink(af->tmp);
        return tcb_fail(err, TCB_ERR_IO, "%s: write failed: %s", af->path, strerror(e));
    }
    return tcb_publish(af->tmp, af->path, err);
}

void tcb_atomic_abort(tcb_atomic_file *af)
{
    if (af->fp) fclose(af->fp);
    af->fp = NULL;
    if (af->tmp[0]) unlink(af->tmp);
}

int tcb_atomic_fail(tcb_atomic_file *af, tcb_error *err)
{
    int e = errno;
    tcb_atomic_abort(af);
    return tcb_fail(err, TCB_ERR_IO, "%s: write failed: %s", af->path, strerror(e));
}

int tcb_write_file_atomic(const char *path, const void *data, size_t len, tcb_error *err)
{
    tcb_atomic_file af;
    int rc = tcb_atomic_open(&af, path, err);
    if (rc) return rc;
    if (len && fwrite(data, 1, len, af.fp) != len) return tcb_atomic_fail(&af, err);
    return tcb_atomic_commit(&af, err);
}

int tcb_read_file(const char *path, char **data, size_t *len, tcb_error *err)
{
    *data = NULL;
    if (len) *len = 0;
    FILE *f = fopen(path, "rb");
    if (!f) return tcb_fail(err, TCB_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    struct stat st;
    if (fstat(fileno(f), &st) != 0 || !S_ISREG(st.st_mode)) {
        fclose(f);
        return tcb_fail(err, TCB_ERR_IO, "%s: not a regular file", path);
    }
    size_t size = (size_t)st.st_size;
    char *buf = malloc(size + 1);
    if (!buf) {
        fclose(f);
        return tcb_fail(err, TCB_ERR_NOMEM, "%s: cannot allocate %zu bytes", path, size + 1);
    }
    size_t got = fread(buf, 1, size, f);
    int failed = ferror(f);
    fclose(f);
    if (failed || got != size) {
        free(buf);
        return tcb_fail(err, TCB_ERR_IO, "%s: read failed", path);
    }
    buf[size] = '\0';
    *data = buf;
    if (len) *len = size;
    return TCB_OK;
}

/* A temporary ("….tmp-<pid>-XXXXXX") whose writer is gone; names without a
 * parsable pid count as stale. A reused pid keeps debris, never loses data. */
static int is_stale_temp(const char *name)
{
    const char *t = strstr(name, ".tmp-");
    if (!t) return 0;
    char *end;
    errno = 0;
    long pid = strtol(t + 5, &end, 10);
    if (errno || end == t + 5 || *end != '-' || pid <= 0) return 1;
    return kill((pid_t)pid, 0) != 0 && errno == ESRCH;
}

void tcb_remove_stale_temps(const char *dir, const char *prefix)
{
    DIR *d = opendir(dir);
    if (!d) return;
    size_t plen = strlen(prefix);
    for (struct dirent *e; (e = readdir(d));) {
        char victim[TCB_PATH_MAX];
        if (strncmp(e->d_name, prefix, plen) != 0 || !is_stale_temp(e->d_name)) continue;
        if ((size_t)snprintf(victim, sizeof victim, "%s/%s", dir, e->d_name) < sizeof victim &&
            tcb_is_file(victim))
            remove(victim);
    }
    closedir(d);
}

void tcb_remove_stale_temps_of(const char *path)
{
    char dir[TCB_PATH_MAX], prefix[TCB_PATH_MAX];
    snprintf(dir, sizeof dir, "%s", path);
    char *slash = strrchr(dir, '/');
    const char *base = slash ? slash + 1 : path;
    if ((size_t)snprintf(prefix, sizeof prefix, "%s.tmp-", base) >= sizeof prefix) return;
    if (slash) *slash = '\0';
    tcb_remove_stale_temps(slash ? dir : ".", prefix);
}
