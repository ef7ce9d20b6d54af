/* Occupancy Flow's point-cloud sequences (github autonomousvision/
 * occupancy_flow: scripts/sample_mesh.py writes them, im2mesh/data/
 * fields.py, PointCloudSubseqField, reads them): <dir>/pcl_seq/NNNNNNNN.npz,
 * one a frame, each with
 *     points  (N, 3) float16   the frame's points, normalised by the frame's
 *                              own box: (world - loc) / scale
 *     loc     (3,)             that box's centre
 *     scale   ()               its largest extent
 * the N points drawn once on the first mesh (faces and barycentric weights)
 * and reused in every frame, so point k is the same surface point in every
 * frame. Their loader maps frame t into frame 0's normalised coordinates,
 * (loc_t + scale_t points_t - loc_0) / scale_0; tcbench keeps the world
 * coordinates loc_t + scale_t points_t and normalises as the config says.
 *
 * A sequence of points without faces (n_faces 0): its vertices are `keep`
 * of the N points, the same in every frame (a seeded choice: the rank
 * metric compares every vertex with every other, which 100 000 points
 * would make 10^10 distances a pair). Metrics that need faces (the
 * geodesic error, the reconstruction metrics) are then not computed. */
#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tcb/fsutil.h"
#include "tcb/npz.h"
#include "tcb/rng.h"
#include "tcb/sequence.h"

/* Member `key` of z as doubles in C order into *out (malloc'ed), its shape
 * checked by the caller through *a (freed here). */
static int member(const tcb_npz *z, const char *key, tcb_npy *a, double **out, tcb_error *err)
{
    char name[32];
    snprintf(name, sizeof name, "%s.npy", key);
    int k = tcb_npz_find(z, name);
    if (k < 0) return tcb_fail(err, TCB_ERR_INPUT, "%s: no array '%s' (an Occupancy Flow frame has points, loc and scale)", z->path, key);
    int rc = tcb_npz_read(z, k, a, err);
    if (rc) return rc;
    if (a->kind != 'f' || a->count > (uint64_t)INT32_MAX) {
        tcb_npy_free(a);
        return tcb_fail(err, TCB_ERR_INPUT, "%s: %s: expected floats, got %s", z->path, key, a->descr);
    }
    *out = malloc((size_t)(a->count ? a->count : 1) * sizeof **out);
    rc = *out ? tcb_npy_to_double(a, *out, err) : tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", z->path);
    if (rc) tcb_error_prefix(err, "%s: %s: ", z->path, key), free(*out), *out = NULL;
    return rc;
}

int tcb_pcl_seq_frame_read(const char *path, int want, float **world, int *n, tcb_error *err)
{
    *world = NULL, *n = 0;
    tcb_npz z;
    int rc = tcb_npz_open(path, &z, err);
    if (rc) return rc;
    tcb_npy pa = {0}, la = {0}, sa = {0};
    double *p = NULL, *loc = NULL, *scale = NULL;
    rc = member(&z, "points", &pa, &p, err);
    if (!rc) rc = member(&z, "loc", &la, &loc, err);
    if (!rc) rc = member(&z, "scale", &sa, &scale, err);
    char shape[64] = "";
    if (!rc) tcb_npy_shape_text(&pa, shape, sizeof shape);
    if (!rc && (pa.ndim != 2 || pa.shape[1] != 3 || pa.shape[0] < 1))
        rc = tcb_fail(err, TCB_ERR_INPUT, "%s: points: expected an (N, 3) array, got %s", path, shape);
    if (!rc && want > 0 && pa.shape[0] != (uint64_t)want)
        rc = tcb_fail(err, TCB_ERR_INPUT, "%s: points: %s, but the first frame has %d points", path, shape, want);
    if (!rc && la.count != 3) rc = tcb_fail(err, TCB_ERR_INPUT, "%s: loc: expected 3 numbers", path);
    if (!rc && sa.count != 1) rc = tcb_fail(err, TCB_ERR_INPUT, "%s: scale: expected one number", path);
    if (!rc && (!isfinite(scale[0]) || !(scale[0] > 0) || !isfinite(loc[0] + loc[1] + loc[2])))
        rc = tcb_fail(err, TCB_ERR_INPUT, "%s: loc (%g, %g, %g) and scale %g: expected finite, scale > 0", path,
                      loc[0], loc[1], loc[2], scale[0]);
    float *out = NULL;
    if (!rc && !(out = malloc((size_t)pa.count * sizeof *out)))
        rc = tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory for %s points", path, shape);
    for (uint64_t i = 0; !rc && i < pa.count; i++) {
        double w = loc[i % 3] + scale[0] * p[i];
        if (!isfinite(w) || fabs(w) > 1e18)
            rc = tcb_fail(err, TCB_ERR_INPUT, "%s: points: point %llu has coordinate %g", path,
                          (unsigned long long)(i / 3), p[i]);
        else
            out[i] = (float)w;
    }
    if (!rc) *world = out, *n = (int)pa.shape[0];
    else free(out);
    free(p), free(loc), free(scale);
    tcb_npy_free(&pa), tcb_npy_free(&la), tcb_npy_free(&sa);
    tcb_npz_close(&z);
    return rc;
}

typedef struct npz_frame {
    char name[256];
    unsigned long long number;
} npz_frame;

static int cmp_frame(const void *a, const void *b)
{
    unsigned long long x = ((const npz_frame *)a)->number, y = ((const npz_frame *)b)->number;
    return (x > y) - (x < y);
}

/* The *.npz of dir, each named by its number, sorted; gaps are missing frames. */
static int list_frames(const char *dir, npz_frame **out, int *n, tcb_error *err)
{
    *out = NULL, *n = 0;
    DIR *d = opendir(dir);
    if (!d) return tcb_fail(err, TCB_ERR_IO, "%s: %s", dir, strerror(errno));
    int cap = 0, rc = TCB_OK;
    for (struct dirent *e; !rc && (e = readdir(d));) {
        size_t len = strlen(e->d_name);
        if (len < 5 || strcmp(e->d_name + len - 4, ".npz") || len >= sizeof((*out)->name)) continue;
        char *end;
        unsigned long long num = strtoull(e->d_name, &end, 10);
        if (end != e->d_name + len - 4 || end == e->d_name) {
            rc = tcb_fail(err, TCB_ERR_INPUT, "%s/%s: expected a frame number as the name (00000080.npz)", dir, e->d_name);
            break;
        }
        if (*n == cap) {
            cap = cap ? 2 * cap : 32;
            npz_frame *grown = realloc(*out, (size_t)cap * sizeof *grown);
            if (!grown) {
                rc = tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", dir);
                break;
            }
            *out = grown;
        }
        snprintf((*out)[*n].name, sizeof (*out)[*n].name, "%s", e->d_name);
        (*out)[(*n)++].number = num;
    }
    closedir(d);
    if (!rc && *n < 2) rc = tcb_fail(err, TCB_ERR_INPUT, "%s: %d .npz frames (a sequence needs two)", dir, *n);
    if (!rc) qsort(*out, (size_t)*n, sizeof **out, cmp_frame);
    for (int f = 1; !rc && f < *n; f++)
        if ((*out)[f].number != (*out)[f - 1].number + 1)
            rc = tcb_fail(err, TCB_ERR_INPUT, "%s: frame %08llu is missing (between %s and %s)", dir,
                          (*out)[f - 1].number + 1, (*out)[f - 1].name, (*out)[f].name);
    if (rc) free(*out), *out = NULL, *n = 0;
    return rc;
}

/* A seeded permutation of [0, n) whose first `keep` are the points kept
 * (the same in every frame). */
static int *choose(int n, int keep, const char *name)
{
    int *idx = malloc((size_t)n * sizeof *idx);
    if (!idx) return NULL;
    for (int i = 0; i < n; i++) idx[i] = i;
    char label[TCB_NAME_MAX + 16];
    snprintf(label, sizeof label, "pcl_seq/%s", name);
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 0, label);
    for (int i = 0; i < keep; i++) {
        int j = i + (int)tcb_rng_below(&rng, (uint32_t)(n - i)), t = idx[i];
        idx[i] = idx[j], idx[j] = t;
    }
    return idx;
}

int tcb_sequence_read_pcl_seq(const char *dir, const char *name, int keep, tcb_sequence *out, tcb_error *err)
{
    memset(out, 0, sizeof *out);
    char frames_dir[TCB_PATH_MAX];
    int rc = tcb_path_join(frames_dir, sizeof frames_dir, err, "%s/pcl_seq", dir);
    if (rc) return rc;
    npz_frame *frames;
    int nf;
    if ((rc = list_frames(frames_dir, &frames, &nf, err))) return rc;
    int n = 0, *idx = NULL;
    for (int f = 0; !rc && f < nf; f++) {
        char path[TCB_PATH_MAX];
        float *world;
        int got;
        if ((rc = tcb_path_join(path, sizeof path, err, "%s/%s", frames_dir, frames[f].name))) break;
        if ((rc = tcb_pcl_seq_frame_read(path, n, &world, &got, err))) break;
        if (f == 0) {
            n = got;
            int kept = keep > 0 && keep < n ? keep : n;
            idx = choose(n, kept, name);
            rc = idx ? tcb_sequence_alloc(out, name, nf, kept, 0, err) : tcb_fail(err, TCB_ERR_NOMEM, "out of memory");
        }
        for (int v = 0; !rc && v < out->n_verts; v++)
            memcpy(out->verts + ((size_t)f * out->n_verts + v) * 3, world + 3 * (size_t)idx[v], 3 * sizeof(float));
        free(world);
    }
    free(idx), free(frames);
    if (rc) tcb_sequence_free(out);
    return rc;
}

int tcb_sequence_probe_pcl_seq(const char *dir, int keep, int *n_frames, int *n_verts, tcb_error *err)
{
    char frames_dir[TCB_PATH_MAX], path[TCB_PATH_MAX];
    npz_frame *frames;
    int nf, n = 0;
    float *world = NULL;
    int rc = tcb_path_join(frames_dir, sizeof frames_dir, err, "%s/pcl_seq", dir);
    if (rc || (rc = list_frames(frames_dir, &frames, &nf, err))) return rc;
    rc = tcb_path_join(path, sizeof path, err, "%s/%s", frames_dir, frames[0].name);
    if (!rc) rc = tcb_pcl_seq_frame_read(path, 0, &world, &n, err);
    free(world), free(frames);
    if (!rc) *n_frames = nf, *n_verts = keep > 0 && keep < n ? keep : n;
    return rc;
}
