/* The clip folders DynoSurf, PDG and Neu-PiG distribute (DynoSurf's README
 * links the preprocessed data: 32 AMA, 109 DFAUST and 89
 * DeformingThings4D clips): per clip, gt/NNNN.obj GT meshes of one
 * topology and pcl_seqs/NNNN.npy the GT points that correspond across
 * frames, which their evaluation tracks (evaluation/utils.py,
 * eval_correspondences_mesh). The input point clouds beside them
 * (point_clouds/NNNN.ply) are not read: the papers' runs sample their
 * inputs from gt/ (`--target obj -np 5000`), as tcbench's pools do. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "datasets/objdir.h"
#include "tcb/fsutil.h"
#include "tcb/npy.h"
#include "tcb/sequence.h"

int tcb_track_frame_parse(const void *buf, size_t len, int want, float **pts, int *n, tcb_error *err)
{
    *pts = NULL, *n = 0;
    tcb_npy a;
    int rc = tcb_npy_parse(buf, len, &a, err);
    if (rc) return rc;
    char shape[64];
    tcb_npy_shape_text(&a, shape, sizeof shape);
    if (a.kind != 'f' || a.ndim != 2 || a.shape[1] != 3 || a.shape[0] < 1 || a.shape[0] > INT32_MAX / 3)
        return tcb_fail(err, TCB_ERR_INPUT, "expected an (N, 3) float array of points, got %s %s", a.descr, shape);
    if (want > 0 && a.shape[0] != (uint64_t)want)
        return tcb_fail(err, TCB_ERR_INPUT, "%s points, but the first frame has %d", shape, want);
    double *v = malloc((size_t)a.count * sizeof *v);
    float *out = malloc((size_t)a.count * sizeof *out);
    rc = v && out ? tcb_npy_to_double(&a, v, err) : tcb_fail(err, TCB_ERR_NOMEM, "out of memory for %s points", shape);
    for (uint64_t i = 0; !rc && i < a.count; i++) {
        if (!isfinite(v[i]) || fabs(v[i]) > 1e18)
            rc = tcb_fail(err, TCB_ERR_INPUT, "point %llu has coordinate %g", (unsigned long long)(i / 3), v[i]);
        out[i] = (float)v[i];
    }
    free(v);
    if (rc) {
        free(out);
        return rc;
    }
    *pts = out, *n = (int)a.shape[0];
    return TCB_OK;
}

/* <dir>/pcl_seqs/<number as %04d>.npy of every listed frame into s->track. */
static int read_tracks(const char *dir, const tcb_objdir_frame *frames, tcb_sequence *s, tcb_error *err)
{
    int rc = TCB_OK;
    for (int f = 0; f < s->n_frames && !rc; f++) {
        char path[TCB_PATH_MAX];
        if ((rc = tcb_path_join(path, sizeof path, err, "%s/pcl_seqs/%04llu.npy", dir, frames[f].number))) break;
        if (!tcb_is_file(path)) {
            rc = tcb_fail(err, TCB_ERR_INPUT, "%s: no such file (gt/%s has no tracked points)", path, frames[f].name);
            break;
        }
        char *buf;
        size_t len;
        if ((rc = tcb_read_file(path, &buf, &len, err))) break;
        float *pts;
        int n;
        rc = tcb_track_frame_parse(buf, len, s->n_track, &pts, &n, err);
        free(buf);
        if (rc) {
            tcb_error_prefix(err, "%s: ", path);
            break;
        }
        if (!s->track) {
            s->n_track = n;
            s->track = malloc((size_t)s->n_frames * (size_t)n * 3 * sizeof *s->track);
            if (!s->track) rc = tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory for %d points a frame", path, n);
        }
        if (!rc) memcpy(s->track + (size_t)f * (size_t)n * 3, pts, (size_t)n * 3 * sizeof *pts);
        free(pts);
    }
    return rc;
}

/* Their scripts read frames 0000 … by number (range(17)): a gap is a
 * missing frame, not a shorter clip. */
static int check_numbering(const char *gt, const tcb_objdir_frame *frames, int n, tcb_error *err)
{
    for (int f = 0; f < n; f++)
        if (frames[f].number != (unsigned long long)f)
            return tcb_fail(err, TCB_ERR_INPUT, "%s: frame %04d is missing (the next is %s; a clip's frames are "
                            "numbered from 0000 without gaps)", gt, f, frames[f].name);
    return TCB_OK;
}

int tcb_sequence_read_clipdir(const char *dir, const char *name, tcb_sequence *out, tcb_error *err)
{
    memset(out, 0, sizeof *out);
    char gt[TCB_PATH_MAX], pcl[TCB_PATH_MAX];
    int rc = tcb_path_join(gt, sizeof gt, err, "%s/gt", dir);
    if (!rc) rc = tcb_path_join(pcl, sizeof pcl, err, "%s/pcl_seqs", dir);
    if (rc) return rc;
    if (!tcb_is_dir(gt))
        return tcb_fail(err, TCB_ERR_INPUT, "%s: no such directory (a clip folder holds its GT meshes in gt/)", gt);
    tcb_objdir_frame *frames;
    int n;
    if ((rc = tcb_objdir_list(gt, &frames, &n, err))) return rc;
    rc = check_numbering(gt, frames, n, err);
    if (!rc) rc = tcb_objdir_read(gt, frames, n, name, out, err);
    if (!rc && tcb_is_dir(pcl)) rc = read_tracks(dir, frames, out, err);
    free(frames);
    if (rc) tcb_sequence_free(out);
    return rc;
}
