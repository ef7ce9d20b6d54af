/* The fingerprint of a sequence as a method sees it, which a file saved for
 * one cell carries so that it is never taken for another's: two sequences
 * of one frame count (every synthetic one of a config), or one sequence
 * under another normalization or pool, must not share a training. */
#include <string.h>

#include "tcb/hash.h"
#include "tcb/sequence.h"

uint64_t tcb_sequence_fingerprint(const tcb_sequence *s)
{
    size_t nv = (size_t)s->n_frames * (size_t)s->n_verts * 3, np = (size_t)s->n_frames * (size_t)s->pool_size * 3;
    int32_t sizes[6] = {s->n_frames, s->n_verts, s->n_faces, s->pool_size, s->input_points,
                        s->draw_with_replacement};
    uint64_t h = tcb_fnv1a64(TCB_FNV1A64_OFFSET, s->name, strlen(s->name));
    h = tcb_fnv1a64(h, sizes, sizeof sizes);
    h = tcb_fnv1a64(h, s->verts, nv * sizeof *s->verts);
    h = tcb_fnv1a64(h, s->faces, (size_t)s->n_faces * 3 * sizeof *s->faces);
    if (s->pools) h = tcb_fnv1a64(h, s->pools, np * sizeof *s->pools);
    for (int k = 0; k < s->n_blocks; k++)
        h = tcb_fnv1a64(h, &s->blocks[k].start, sizeof s->blocks[k].start);
    /* Only when given, so that the fingerprints of sequences without input
     * normals (every one before them) stay what their records hold. */
    if (s->input_normals != TCB_INPUT_NORMALS_NONE) {
        int32_t normals = (int32_t)s->input_normals;
        h = tcb_fnv1a64(h, &normals, sizeof normals);
    }
    if (s->track) h = tcb_fnv1a64(h, s->track, (size_t)s->n_frames * (size_t)s->n_track * 3 * sizeof *s->track);
    return h;
}
