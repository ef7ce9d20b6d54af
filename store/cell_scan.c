/* Scanning a run directory for its finished cells. */
#include "tcb/results.h"

#include <dirent.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "tcb/fsutil.h"

typedef struct cell_list {
    tcb_cell_result *v;
    int n, cap;
} cell_list;

static int has_json_suffix(const char *name)
{
    size_t n = strlen(name);
    return n > 5 && !strcmp(name + n - 5, ".json");
}

/* A cell must sit where tcb_cell_path puts it: a copied or renamed file
 * would otherwise be counted twice or under the wrong key. */
static int check_location(const char *run_dir, const char *path, const tcb_cell_result *c,
                          tcb_error *err)
{
    char want[TCB_PATH_MAX];
    int rc = tcb_cell_path(want, sizeof want, run_dir, c->dataset, c->sequence, c->method,
                           c->seed, err);
    if (rc) {
        tcb_error_prefix(err, "%s: ", path);
        return rc;
    }
    if (strcmp(want, path))
        return tcb_fail(err, TCB_ERR_INPUT,
                        "%s: holds the cell %s/%s/%s seed %d, which belongs at %s", path,
                        c->dataset, c->sequence, c->method, c->seed, want);
    return TCB_OK;
}

static int scan_file(const char *run_dir, const char *path, cell_list *l, tcb_error *err)
{
    if (l->n == l->cap) {
        int cap = l->cap ? 2 * l->cap : 64;
        tcb_cell_result *v = realloc(l->v, (size_t)cap * sizeof *v);
        if (!v) return tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", path);
        l->v = v;
        l->cap = cap;
    }
    int rc = tcb_cell_load(path, &l->v[l->n], err);
    if (rc) return rc;
    l->n++;
    return check_location(run_dir, path, &l->v[l->n - 1], err);
}

/* Only *.json files are cells: the temporaries of an atomic write in
 * progress end in ".tmp-<pid>-XXXXXX". Hidden entries are never cells either. */
static int scan_dir(const char *run_dir, const char *dir, cell_list *l, tcb_error *err)
{
    DIR *d = opendir(dir);
    if (!d) return tcb_fail(err, TCB_ERR_IO, "%s: cannot open directory", dir);
    int rc = TCB_OK;
    struct dirent *e;
    while (!rc && (e = readdir(d))) {
        if (e->d_name[0] == '.') continue;
        char path[TCB_PATH_MAX];
        struct stat st;
        if ((rc = tcb_path_join(path, sizeof path, err, "%s/%s", dir, e->d_name))) break;
        if (stat(path, &st)) {
            rc = tcb_fail(err, TCB_ERR_IO, "%s: cannot stat", path);
        } else if (S_ISDIR(st.st_mode)) {
            rc = scan_dir(run_dir, path, l, err);
        } else if (S_ISREG(st.st_mode) && has_json_suffix(e->d_name)) {
            rc = scan_file(run_dir, path, l, err);
        }
    }
    closedir(d);
    return rc;
}

static int cell_cmp(const void *pa, const void *pb)
{
    const tcb_cell_result *a = pa, *b = pb;
    int c;
    if ((c = strcmp(a->dataset, b->dataset))) return c;
    if ((c = strcmp(a->sequence, b->sequence))) return c;
    if ((c = strcmp(a->method, b->method))) return c;
    return (a->seed > b->seed) - (a->seed < b->seed);
}

int tcb_results_scan(const char *run_dir, tcb_cell_result **cells, int *n, tcb_error *err)
{
    *cells = NULL;
    *n = 0;
    char dir[TCB_PATH_MAX];
    int rc = tcb_path_join(dir, sizeof dir, err, "%s/cells", run_dir);
    if (rc) return rc;
    if (!tcb_is_dir(dir)) return tcb_fail(err, TCB_ERR_IO, "%s: no such results directory", dir);
    cell_list l = {0};
    rc = scan_dir(run_dir, dir, &l, err);
    if (rc) {
        for (int k = 0; k < l.n; k++) tcb_cell_free(&l.v[k]);
        free(l.v);
        return rc;
    }
    if (l.n > 1) qsort(l.v, (size_t)l.n, sizeof *l.v, cell_cmp);
    *cells = l.v;
    *n = l.n;
    return TCB_OK;
}
