/* A directory of OBJ frames <-> a tcb_sequence, loaded through the cache. */
#include "datasets/objdir.h"

#include <dirent.h>
#include <errno.h>
#include <limits.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

#include "datasets/cache.h"
#include "datasets/strbuf.h"
#include "tcb/fsutil.h"
#include "tcb/mesh_io.h"

/* The last run of digits in name[0..len): "mesh.01" → 1, "mesh_0001" → 1,
 * "take2_frame10" → 10. Returns 0 when there is none or it overflows. */
static int last_number(const char *name, size_t len, unsigned long long *out)
{
    size_t end = len;
    while (end > 0 && (name[end - 1] < '0' || name[end - 1] > '9')) end--;
    if (end == 0) return 0;
    size_t start = end;
    while (start > 0 && name[start - 1] >= '0' && name[start - 1] <= '9') start--;
    unsigned long long x = 0;
    for (size_t i = start; i < end; i++) {
        unsigned d = (unsigned)(name[i] - '0');
        if (x > (ULLONG_MAX - d) / 10) return 0;
        x = x * 10 + d;
    }
    *out = x;
    return 1;
}

static int by_number(const void *a, const void *b)
{
    const tcb_objdir_frame *x = a, *y = b;
    if (x->number != y->number) return x->number < y->number ? -1 : 1;
    return strcmp(x->name, y->name); /* only to name ties deterministically */
}

/* Appends dir/name to the list when it is a regular *.obj file. */
static int consider(const char *dir, const char *name, tcb_objdir_frame **frames, int *n,
                    int *cap, tcb_error *err)
{
    size_t len = strlen(name);
    if (name[0] == '.' || len < 5 || len >= TCB_OBJDIR_NAME_MAX || strcasecmp(name + len - 4, ".obj") != 0)
        return TCB_OK;
    char path[TCB_PATH_MAX];
    struct stat st;
    if (tcb_path_join(path, sizeof path, err, "%s/%s", dir, name)) return TCB_ERR_INPUT;
    if (stat(path, &st) != 0 || !S_ISREG(st.st_mode)) return TCB_OK;
    tcb_objdir_frame fr = {.size = (long long)st.st_size,
                           .mtime_ns = (long long)st.st_mtim.tv_sec * 1000000000LL + st.st_mtim.tv_nsec};
    memcpy(fr.name, name, len + 1);
    if (!last_number(name, len - 4, &fr.number))
        return tcb_fail(err, TCB_ERR_INPUT, "%s: file name has no frame number to order it by", path);
    if (*n == *cap) {
        int cap2 = *cap ? 2 * *cap : 64;
        tcb_objdir_frame *p = realloc(*frames, (size_t)cap2 * sizeof *p);
        if (!p) return tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory listing frames", dir);
        *frames = p;
        *cap = cap2;
    }
    (*frames)[(*n)++] = fr;
    return TCB_OK;
}

static int check_order(const char *dir, const tcb_objdir_frame *frames, int n, tcb_error *err)
{
    if (n == 0) return tcb_fail(err, TCB_ERR_INPUT, "%s: no .obj frames in directory", dir);
    for (int i = 1; i < n; i++)
        if (frames[i].number == frames[i - 1].number)
            return tcb_fail(err, TCB_ERR_INPUT, "%s: %s and %s have the same frame number %llu", dir,
                            frames[i - 1].name, frames[i].name, frames[i].number);
    if (n < 2)
        return tcb_fail(err, TCB_ERR_INPUT, "%s: only one frame (%s); a sequence needs at least 2",
                        dir, frames[0].name);
    return TCB_OK;
}

int tcb_objdir_list(const char *dir, tcb_objdir_frame **frames, int *n, tcb_error *err)
{
    *frames = NULL;
    *n = 0;
    DIR *d = opendir(dir);
    if (!d) return tcb_fail(err, TCB_ERR_IO, "%s: cannot open directory: %s", dir, strerror(errno));
    int cap = 0, rc = TCB_OK;
    for (struct dirent *e; !rc && (e = readdir(d));) rc = consider(dir, e->d_name, frames, n, &cap, err);
    closedir(d);
    if (!rc && *n > 1) qsort(*frames, (size_t)*n, sizeof **frames, by_number);
    if (!rc) rc = check_order(dir, *frames, *n, err);
    if (rc) {
        free(*frames);
        *frames = NULL;
        *n = 0;
    }
    return rc;
}

/* Frame f's mesh must have the topology of frame 0 (already in out). */
static int check_topology(const tcb_sequence *out, const tcb_mesh *m, const char *first,
                          const char *path, tcb_error *err)
{
    if (m->n_verts != out->n_verts)
        return tcb_fail(err, TCB_ERR_INPUT, "%s has %d vertices but %s has %d", path, m->n_verts,
                        first, out->n_verts);
    if (m->n_faces != out->n_faces ||
        memcmp(m->faces, out->faces, (size_t)m->n_faces * 3 * sizeof(int32_t)) != 0)
        return tcb_fail(err, TCB_ERR_INPUT, "%s: faces differ from those of %s", path, first);
    return TCB_OK;
}

/* Parse frame f into out; frame 0 also allocates out with its sizes. */
static int read_frame(const char *dir, const tcb_objdir_frame *frames, int n, int f,
                      const char *name, tcb_sequence *out, tcb_error *err)
{
    char path[TCB_PATH_MAX], first[TCB_PATH_MAX];
    if (tcb_path_join(path, sizeof path, err, "%s/%s", dir, frames[f].name) ||
        tcb_path_join(first, sizeof first, err, "%s/%s", dir, frames[0].name))
        return TCB_ERR_INPUT;
    tcb_mesh m;
    int rc = tcb_obj_read(path, &m, err);
    if (rc) return rc;
    if (f == 0) {
        rc = tcb_sequence_alloc(out, name, n, m.n_verts, m.n_faces, err);
        if (!rc) memcpy(out->faces, m.faces, (size_t)m.n_faces * 3 * sizeof(int32_t));
    } else {
        rc = check_topology(out, &m, first, path, err);
    }
    if (!rc) memcpy(out->verts + (size_t)f * out->n_verts * 3, m.verts, (size_t)m.n_verts * 3 * sizeof(float));
    tcb_mesh_free(&m);
    return rc;
}

int tcb_objdir_read(const char *dir, const tcb_objdir_frame *frames, int n, const char *name,
                    tcb_sequence *out, tcb_error *err)
{
    memset(out, 0, sizeof *out);
    for (int f = 0; f < n; f++) {
        int rc = read_frame(dir, frames, n, f, name, out, err);
        if (rc) {
            tcb_sequence_free(out);
            return rc;
        }
    }
    return TCB_OK;
}

int tcb_objdir_default_name(const char *dir, char name[TCB_NAME_MAX], tcb_error *err)
{
    size_t end = strlen(dir);
    while (end > 1 && dir[end - 1] == '/') end--;
    size_t start = end;
    while (start > 0 && dir[start - 1] != '/') start--;
    if (end - start >= TCB_NAME_MAX)
        return tcb_fail(err, TCB_ERR_INPUT, "%s: directory name too long for a sequence name", dir);
    memcpy(name, dir + start, end - start);
    name[end - start] = '\0';
    return TCB_OK;
}

int tcb_sequence_probe_objdir(const char *dir, int *n_frames, int *n_verts, tcb_error *err)
{
    tcb_objdir_frame *frames;
    int n;
    *n_frames = *n_verts = 0;
    int rc = tcb_objdir_list(dir, &frames, &n, err);
    if (rc) return rc;
    char path[TCB_PATH_MAX];
    tcb_mesh m = {0};
    rc = tcb_path_join(path, sizeof path, err, "%s/%s", dir, frames[0].name);
    if (!rc) rc = tcb_obj_read(path, &m, err);
    if (!rc) *n_frames = n, *n_verts = m.n_verts;
    tcb_mesh_free(&m);
    free(frames);
    return rc;
}

int tcb_sequence_read_objdir(const char *dir, tcb_sequence *out, tcb_error *err)
{
    memset(out, 0, sizeof *out);
    char name[TCB_NAME_MAX];
    tcb_objdir_frame *frames;
    int n, rc = tcb_objdir_default_name(dir, name, err);
    if (rc) return rc;
    if ((rc = tcb_objdir_list(dir, &frames, &n, err))) return rc;
    rc = tcb_objdir_read(dir, frames, n, name, out, err);
    free(frames);
    return rc;
}

int tcb_sequence_write_objdir(const tcb_sequence *s, const char *dir, tcb_error *err)
{
    for (int f = 0; f < s->n_frames; f++) {
        char path[TCB_PATH_MAX];
        if (tcb_path_join(path, sizeof path, err, "%s/mesh_%04d.obj", dir, f)) return TCB_ERR_INPUT;
        int rc = tcb_obj_write(path, tcb_seq_frame(s, f), s->n_verts, s->faces, s->n_faces, err);
        if (rc) return rc;
    }
    return TCB_OK;
}

typedef struct objdir_source {
    const char *dir;
    const tcb_objdir_frame *frames;
    int n;
} objdir_source;

static int read_listed(const void *ctx, const char *name, tcb_sequence *out, tcb_error *err)
{
    const objdir_source *src = ctx;
    return tcb_objdir_read(src->dir, src->frames, src->n, name, out, err);
}

int tcb_sequence_load_objdir(const char *dir, const char *name, const tcb_load_opts *opts, tcb_sequence *out,
                             tcb_error *err)
{
    memset(out, 0, sizeof *out);
    char default_name[TCB_NAME_MAX];
    if (!name) {
        int rc = tcb_objdir_default_name(dir, default_name, err);
        if (rc) return rc;
        name = default_name;
    }
    tcb_objdir_frame *frames;
    int n, rc = tcb_objdir_list(dir, &frames, &n, err);
    if (rc) return rc;
    /* The cache key names every frame file as listed, the list then parsed:
     * the two cannot disagree. */
    tcb_strbuf key = {0};
    for (int i = 0; i < n && !rc; i++)
        if (tcb_sb_printf(&key, "%s %lld %lld\n", frames[i].name, frames[i].size, frames[i].mtime_ns))
            rc = tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", dir);
    objdir_source src = {dir, frames, n};
    if (!rc) rc = tcb_cache_load(name, opts, key.s, read_listed, &src, out, err);
    free(key.s);
    free(frames);
    return rc;
}
