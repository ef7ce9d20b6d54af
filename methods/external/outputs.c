/* The transfer step's files, read with `tcbench score`'s readers (the
 * format is the same: docs/formats.md), so a command's output is judged
 * exactly as a directory of predictions would be. */
#include <string.h>

#include "methods/external/external.h"
#include "tcb/predictions.h"

/* <work>/pred/<k>.npy, or recon_<k>_<which>.npy when which is 'i' or 'j'. */
static int output_path(const ext_method *m, int k, char which, char *out, tcb_error *err)
{
    if (!which) return tcb_path_join(out, TCB_PATH_MAX, err, "%s/%s/%d.npy", m->work, EXT_PRED_DIR, k);
    return tcb_path_join(out, TCB_PATH_MAX, err, "%s/%s/recon_%d_%c.npy", m->work, EXT_PRED_DIR, k, which);
}

/* The command wrote batch pair b's file (which as in output_path)? */
static int present(const ext_method *m, int b, char which, int *yes, tcb_error *err)
{
    char path[TCB_PATH_MAX];
    int rc = output_path(m, m->first + b, which, path, err);
    *yes = !rc && tcb_is_file(path);
    return rc;
}

#define ALL_OR_NONE "reconstructions are written for every pair or for none"

/* Batch pair b's file `which` breaks the protocol: named, with why. */
static int bad_file(const ext_method *m, int b, char which, const char *what, const char *why, tcb_error *err)
{
    char path[TCB_PATH_MAX];
    int rc = output_path(m, m->first + b, which, path, err);
    return rc ? rc : tcb_fail(err, TCB_ERR_INPUT, "%s: %s (%s)", path, what, why);
}

/* Batch pair b's reconstructions (ri, rj: present) agree with the first's. */
static int check_recon(const ext_method *m, int b, int ri, int rj, tcb_error *err)
{
    if (m->has_recon && !(ri && rj)) return bad_file(m, b, ri ? 'j' : 'i', "no such file", ALL_OR_NONE, err);
    if (!m->has_recon && (ri || rj))
        return bad_file(m, b, ri ? 'i' : 'j', "written, but the first pair has no recon_*_i.npy", ALL_OR_NONE, err);
    return TCB_OK;
}

int ext_check_outputs(ext_method *m, tcb_error *err)
{
    int rc = present(m, 0, 'i', &m->has_recon, err);
    for (int b = 0; !rc && b < m->n; b++) {
        int pred = 0, ri = 0, rj = 0;
        rc = present(m, b, 0, &pred, err);
        if (!rc) rc = present(m, b, 'i', &ri, err);
        if (!rc) rc = present(m, b, 'j', &rj, err);
        if (!rc && !pred)
            rc = bad_file(m, b, 0, "no such file", "the transfer step writes one prediction per pair", err);
        if (!rc) rc = check_recon(m, b, ri, rj, err);
    }
    return rc;
}

int ext_read_transfer(ext_method *m, const tcb_sequence *seq, int b, float *out, tcb_error *err)
{
    char path[TCB_PATH_MAX];
    int is_points = 0;
    int rc = output_path(m, m->first + b, 0, path, err);
    if (!rc) rc = tcb_score_read_prediction(path, seq->n_verts, m->ids, out, &is_points, err);
    if (rc || is_points) return rc;
    /* Ids become the points of frame j's vertices: the harness projects a
     * transfer onto frame j's nearest vertex, which is the vertex itself
     * (or one at the very same position, with the same errors). */
    const float *vj = tcb_seq_frame(seq, m->pairs[2 * b + 1]);
    for (int v = 0; v < seq->n_verts; v++) memcpy(out + 3 * (size_t)v, vj + 3 * (size_t)m->ids[v], 3 * sizeof *out);
    return TCB_OK;
}

int ext_read_recon(const ext_method *m, int b, char which, float **pts, int *n, tcb_error *err)
{
    char path[TCB_PATH_MAX];
    int rc = output_path(m, m->first + b, which, path, err);
    return rc ? rc : tcb_score_read_points(path, pts, n, err);
}
