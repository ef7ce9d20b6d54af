/* nricp's per-sequence state setup, shared by fit and run_unit (nricp.c)
 * and load (checkpoint.c): the sizes, the sequence hash and the
 * area-weighted vertex normals every registration reads. Kept apart from
 * the method table so that the checkpoint does not call back into it. */
#include <stdlib.h>

#include "methods/nricp/nricp_internal.h"
#include "tcb/geometry.h"
#include "tcb/meshing.h"

int nricp_prepare(nricp_method *m, const tcb_sequence *seq, tcb_error *err)
{
    if (seq->n_frames < 2 || seq->n_verts < 1)
        return tcb_fail(err, TCB_ERR_INPUT,
                        "nricp: sequence %s has %d frames of %d vertices (need at least 2 frames)", seq->name,
                        seq->n_frames, seq->n_verts);
    m->n_frames = seq->n_frames, m->n_verts = seq->n_verts;
    nricp_chains_free(&m->chains); /* announced for the model this replaces */
    nricp_ahead_free(&m->ahead);
    m->seq_hash = nricp_sequence_hash(seq);
    size_t frame = (size_t)seq->n_verts * 3;
    free(m->normals);
    m->normals = malloc((size_t)seq->n_frames * frame * sizeof *m->normals);
    if (!m->normals) return tcb_fail(err, TCB_ERR_NOMEM, "nricp: out of memory for normals");
    /* A sequence of points alone: normals estimated from the points (PCA,
     * oriented), where a mesh's come from its faces. */
    int rc = TCB_OK;
    for (int f = 0; f < seq->n_frames && !rc; f++)
        if (seq->n_faces)
            tcb_vertex_normals(tcb_seq_frame(seq, f), seq->n_verts, seq->faces, seq->n_faces, m->normals + f * frame);
        else
            rc = tcb_estimate_normals(tcb_seq_frame(seq, f), seq->n_verts, TCB_NORMALS_K, m->normals + f * frame, err);
    return rc;
}
