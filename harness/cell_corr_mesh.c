/* DynoSurf's Corr of a clip, as its evaluation computes it
 * (evaluation/utils.py, eval_correspondences_mesh): the method's surface
 * of the clip's frame 0 matched once to the nearest GT points, then
 * followed through frames 1-16 by vertex index. It needs surfaces of one
 * topology through the clip (a template moved, a fixed chart grid); a
 * method whose vertex count changes gets none (NAN), as DynoSurf's script
 * skips such a frame. The surfaces are those the reconstruction metrics
 * score (the same streams), in the sequence's frame, where DynoSurf's and
 * Neu-PiG's scripts measure it (docs/protocol.md, "The clip protocol"). */
#include <math.h>
#include <stdlib.h>

#include "harness/harness_internal.h"

/* The GT points DynoSurf's script tracks: the dataset's tracked points
 * (the authors' pcl_seqs) where it has them, else the GT vertices. */
static int n_truth(const tcb_sequence *seq) { return seq->track ? seq->n_track : seq->n_verts; }
static const float *truth(const tcb_sequence *seq, int frame)
{
    return seq->track ? seq->track + (size_t)frame * seq->n_track * 3 : tcb_seq_frame(seq, frame);
}

/* The surface of `frame` into *m; a failure is the method's. */
static int clip_surface(const tcb_cell_job *job, void *self, int frame, tcb_uv_mesh *m, tcb_error *merr)
{
    tcb_rng rng;
    return tcb_cell_method_surface(job, self, frame, &rng, m, merr);
}

void tcb_cell_corr_mesh(const tcb_cell_job *job, void *self, int c, tcb_clip_record *rec, tcb_error *merr,
                        tcb_error *herr)
{
    const tcb_sequence *seq = job->seq;
    int s = job->clips->starts[c];
    rec->corr_mesh = NAN;
    tcb_uv_mesh first, m;
    if (clip_surface(job, self, s, &first, merr)) return;
    int32_t *ind = malloc((size_t)first.n_verts * sizeof *ind);
    int rc = ind ? tcb_corr_mesh_match(first.verts, first.n_verts, truth(seq, s), n_truth(seq), ind, herr)
                 : tcb_fail(herr, TCB_ERR_NOMEM, "out of memory for %d surface vertices", first.n_verts);
    double sum = 0;
    int same_topology = 1;
    for (int t = 1; !rc && same_topology && t < TCB_CLIP_FRAMES; t++) {
        if ((rc = clip_surface(job, self, s + t, &m, merr))) break;
        same_topology = m.n_verts == first.n_verts;
        if (same_topology) sum += tcb_corr_mesh_frame(m.verts, m.n_verts, truth(seq, s + t), ind);
        tcb_uv_mesh_free(&m);
    }
    if (!rc && same_topology) rec->corr_mesh = sum / (TCB_CLIP_FRAMES - 1);
    free(ind);
    tcb_uv_mesh_free(&first);
}
