/* The predictions of `tcbench score` (tcb/score.h), a directory or an
 * .npz: which files or members they must hold, and one array read into
 * vertex ids or points; and a file of surface samples (the external
 * method's reconstructions). Every error names the file (and the member). */
#include <dirent.h>
#include <inttypes.h>
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "tcb/fsutil.h"
#include "tcb/nn.h"
#include "tcb/npy.h"
#include "tcb/npz.h"
#include "tcb/predictions.h"

/* k when name is "<k>.npy" written as the format names files and members
 * (no sign, no leading zero; LONG_MAX past nine digits), else -1. */
static long pair_file_index(const char *name)
{
    size_t n = strspn(name, "0123456789");
    if (n == 0 || strcmp(name + n, ".npy") || (name[0] == '0' && n > 1)) return -1;
    return n > 9 ? LONG_MAX : strtol(name, NULL, 10);
}

/* The prediction directory: dir holds 0.npy … <n_pairs-1>.npy and no
 * <k>.npy beyond (the split's path is for the messages). Errors name the
 * file. */
static int check_dir(const char *dir, int n_pairs, const char *split_path, tcb_error *err)
{
    char path[TCB_PATH_MAX];
    if (!tcb_is_dir(dir)) return tcb_fail(err, TCB_ERR_IO, "%s: no such directory", dir);
    for (int k = 0; k < n_pairs; k++) {
        int rc = tcb_path_join(path, sizeof path, err, "%s/%d.npy", dir, k);
        if (rc) return rc;
        if (!tcb_is_file(path))
            return tcb_fail(err, TCB_ERR_IO, "%s: no such file (one file per pair of %s: 0.npy to %d.npy)", path,
                            split_path, n_pairs - 1);
    }
    /* A file past the split's end means predictions for another split. */
    DIR *d = opendir(dir);
    if (!d) return tcb_fail(err, TCB_ERR_IO, "%s: cannot list the directory", dir);
    int rc = TCB_OK;
    for (struct dirent *e; !rc && (e = readdir(d));) {
        if (pair_file_index(e->d_name) >= n_pairs)
            rc = tcb_fail(err, TCB_ERR_INPUT, "%s/%s: %s has only %d pairs (0.npy to %d.npy): predictions for another split?",
                          dir, e->d_name, split_path, n_pairs, n_pairs - 1);
    }
    closedir(d);
    return rc;
}

/* Vertex ids: integers (any width and byte order), each in [0, nv). */
static int read_ids(const tcb_npy *a, int nv, int32_t *pred, tcb_error *err)
{
    if (a->kind != 'i' && a->kind != 'u')
        return tcb_fail(err, TCB_ERR_INPUT, "dtype %s: vertex ids (shape (%d,)) must be integers%s", a->descr, nv,
                        a->kind == 'f' ? " (floats are not rounded to ids)" : "");
    int64_t *ids = malloc((size_t)nv * sizeof *ids);
    if (!ids) return tcb_fail(err, TCB_ERR_NOMEM, "out of memory for %d ids", nv);
    int rc = tcb_npy_to_int64(a, ids, err);
    for (int k = 0; !rc && k < nv; k++) {
        if (ids[k] < 0 || ids[k] >= nv)
            rc = tcb_fail(err, TCB_ERR_INPUT, "element %d: vertex id %" PRId64 " out of range [0, %d)", k, ids[k], nv);
        pred[k] = (int32_t)ids[k];
    }
    free(ids);
    return rc;
}

/* Points: float32 or float64, finite, within the nearest-vertex search's
 * range. Methods transfer float32 points, so a float64 point is rounded to
 * the nearest float32, the precision every method's transfer has. */
static int read_points(const tcb_npy *a, int nv, float *moved, tcb_error *err)
{
    if (a->kind != 'f')
        return tcb_fail(err, TCB_ERR_INPUT, "dtype %s: points (shape (%d, 3)) must be float32 or float64", a->descr,
                        nv);
    size_t n = (size_t)nv * 3;
    double *xyz = malloc(n * sizeof *xyz);
    if (!xyz) return tcb_fail(err, TCB_ERR_NOMEM, "out of memory for %d points", nv);
    int rc = tcb_npy_to_double(a, xyz, err);
    for (size_t k = 0; !rc && k < n; k++) {
        if (!(fabs(xyz[k]) <= TCB_NN_COORD_MAX))
            rc = tcb_fail(err, TCB_ERR_INPUT, "point %zu, coordinate %zu: %s", k / 3, k % 3,
                          isnan(xyz[k]) ? "NaN" : isinf(xyz[k]) ? "infinite" : "beyond ±1e18");
        moved[k] = (float)xyz[k];
    }
    free(xyz);
    return rc;
}

int tcb_score_prediction_of(const tcb_npy *a, int nv, int32_t *pred, float *moved, int *is_points, tcb_error *err)
{
    char shape[64];
    tcb_npy_shape_text(a, shape, sizeof shape);
    *is_points = a->ndim == 2;
    if (a->ndim == 1 && a->shape[0] == (uint64_t)nv) return read_ids(a, nv, pred, err);
    if (a->ndim == 2 && a->shape[0] == (uint64_t)nv && a->shape[1] == 3) return read_points(a, nv, moved, err);
    return tcb_fail(err, TCB_ERR_INPUT, "shape %s: expected (%d,) vertex ids or (%d, 3) points (one per vertex of the frame)",
                    shape, nv, nv);
}

int tcb_score_read_prediction(const char *path, int nv, int32_t *pred, float *moved, int *is_points, tcb_error *err)
{
    tcb_npy a;
    int rc = tcb_npy_load(path, &a, err); /* its errors name the file */
    if (rc) return rc;
    rc = tcb_score_prediction_of(&a, nv, pred, moved, is_points, err);
    tcb_npy_free(&a);
    if (rc) tcb_error_prefix(err, "%s: ", path);
    return rc;
}

int tcb_score_read_points(const char *path, float **pts, int *n, tcb_error *err)
{
    *pts = NULL, *n = 0;
    tcb_npy a;
    int rc = tcb_npy_load(path, &a, err); /* its errors name the file */
    if (rc) return rc;
    char shape[64];
    tcb_npy_shape_text(&a, shape, sizeof shape);
    if (a.ndim != 2 || a.shape[1] != 3 || a.shape[0] < 1 || a.shape[0] > INT_MAX / 3)
        rc = tcb_fail(err, TCB_ERR_INPUT, "shape %s: expected (M, 3) points, M >= 1", shape);
    else if (!(*pts = malloc((size_t)a.shape[0] * 3 * sizeof **pts)))
        rc = tcb_fail(err, TCB_ERR_NOMEM, "out of memory for %s points", shape);
    else
        rc = read_points(&a, (int)a.shape[0], *pts, err);
    if (!rc) *n = (int)a.shape[0];
    tcb_npy_free(&a);
    if (rc) {
        free(*pts);
        *pts = NULL;
        tcb_error_prefix(err, "%s: ", path);
    }
    return rc;
}

/* ---- the sources: a directory, an .npz */

static int dir_read(void *ctx, int k, tcb_npy *a, char name[TCB_PATH_MAX], tcb_error *err)
{
    int rc = tcb_path_join(name, TCB_PATH_MAX, err, "%s/%d.npy", (const char *)ctx, k);
    return rc ? rc : tcb_npy_load(name, a, err);
}

/* An open archive and, for each pair, its member's index. */
typedef struct npz_source {
    tcb_npz z;
    int *member;
} npz_source;

static int npz_read(void *ctx, int k, tcb_npy *a, char name[TCB_PATH_MAX], tcb_error *err)
{
    const npz_source *src = ctx;
    snprintf(name, TCB_PATH_MAX, "%s: %s", src->z.path, src->z.members[src->member[k]].name);
    return tcb_npz_read(&src->z, src->member[k], a, err);
}

/* A member that is no pair's: np.savez's positional names get the fix. */
static int surplus_member(const tcb_npz *z, const char *name, int n_pairs, const char *split_path, tcb_error *err)
{
    if (!strncmp(name, "arr_", 4))
        return tcb_fail(err, TCB_ERR_INPUT,
                        "%s: member %s: members are named by the pair index (0.npy to %d.npy): "
                        "np.savez(path, **{str(k): a for k, a in enumerate(arrays)}), not np.savez(path, *arrays)",
                        z->path, name, n_pairs - 1);
    return tcb_fail(err, TCB_ERR_INPUT, "%s: member %s: not a pair of %s (0.npy to %d.npy): predictions for another split?",
                    z->path, name, split_path, n_pairs - 1);
}

/* Every member is pair k's "<k>.npy" for one k < n_pairs, once; every pair has one. */
static int map_members(npz_source *src, int n_pairs, const char *split_path, tcb_error *err)
{
    const tcb_npz *z = &src->z;
    for (int k = 0; k < n_pairs; k++) src->member[k] = -1;
    for (int m = 0; m < z->n; m++) {
        long k = pair_file_index(z->members[m].name);
        if (k < 0 || k >= n_pairs) return surplus_member(z, z->members[m].name, n_pairs, split_path, err);
        if (src->member[k] >= 0) return tcb_fail(err, TCB_ERR_INPUT, "%s: member %s appears twice", z->path, z->members[m].name);
        src->member[k] = m;
    }
    for (int k = 0; k < n_pairs; k++)
        if (src->member[k] < 0)
            return tcb_fail(err, TCB_ERR_INPUT, "%s: no member %d.npy (one per pair of %s: 0.npy to %d.npy)", z->path, k,
                            split_path, n_pairs - 1);
    return TCB_OK;
}

static int open_npz(const char *path, int n_pairs, const char *split_path, tcb_predictions *p, tcb_error *err)
{
    npz_source *src = calloc(1, sizeof *src);
    if (!src || !(src->member = malloc((size_t)n_pairs * sizeof *src->member))) {
        free(src);
        return tcb_fail(err, TCB_ERR_NOMEM, "out of memory");
    }
    p->ctx = src;
    int rc = tcb_npz_open(path, &src->z, err);
    if (!rc) rc = map_members(src, n_pairs, split_path, err);
    if (rc) tcb_predictions_close(p);
    return rc;
}

int tcb_predictions_open(const char *path, int n_pairs, const char *split_path, tcb_predictions *p, tcb_error *err)
{
    int dir = tcb_is_dir(path);
    if (!dir && !tcb_is_file(path))
        return tcb_fail(err, TCB_ERR_IO, "%s: no such file or directory (a directory of <k>.npy or an .npz)", path);
    *p = (tcb_predictions){dir ? dir_read : npz_read, NULL, dir ? "pred_dir" : "pred_file", path, "scored from files"};
    if (!dir) return open_npz(path, n_pairs, split_path, p, err);
    p->ctx = (void *)path;
    return check_dir(path, n_pairs, split_path, err);
}

void tcb_predictions_close(tcb_predictions *p)
{
    if (p->read == npz_read && p->ctx) {
        npz_source *src = p->ctx;
        tcb_npz_close(&src->z);
        free(src->member);
        free(src);
    }
    p->ctx = NULL;
}
