/* The evaluation pass of the atlas family (reference-protocol §5.3 as
 * coded): both shapes of a pair decoded at regular UV points, collapsed
 * patches dropped, the survivors decoded again at a denser regular set. */
#ifndef TCB_ATLAS_EVAL_H
#define TCB_ATLAS_EVAL_H

#include "methods/atlas/model.h"
#include "methods/atlas/uv_regular.h"
#include "tcb/error.h"

#define TCB_ATLAS_EVAL_POINTS 3125 /* n_pts of the protocol */

/* What the evaluation keeps from pair to pair: the UV sets of the fit's
 * seed and the two decoding workspaces. A workspace holds the encoder's
 * activations of both clouds (tens of MB at N = 2 500); made and freed for
 * every pair, the allocator handed those pages back and faulted them in
 * again each time: 2.1 M page faults and 3.2x the CPU time of a 500-pair
 * evaluation after a training (perf stat, mca tiny on the synthetic walk). */
typedef struct tcb_atlas_eval_state {
    tcb_atlas_uv_cache uvc;
    tcb_atlas_work *work[2]; /* first pass, second pass; remade when a size changes */
} tcb_atlas_eval_state;

void tcb_atlas_eval_state_init(tcb_atlas_eval_state *s, uint64_t seed);
void tcb_atlas_eval_state_free(tcb_atlas_eval_state *s);

/* clouds [2][N][3] (the input clouds of frames i and j). First pass:
 * ⌊n_pts/P⌋ regular points tiled over every patch → φ, φ_u, φ_v → the kept
 * patches (collapse.h). Second pass: m' = ⌊n_pts/P'⌋ regular points tiled
 * over all P patches, of which the kept patches' rows are returned (the
 * same points as decoding only the kept patches). *pred is malloc'ed
 * [2][*n][3]: frame i's points, then frame j's at the same UV samples. */
int tcb_atlas_eval_pair(const tcb_atlas_model *m, tcb_atlas_eval_state *s, const float *clouds,
                        int N, float **pred, int *n, tcb_error *err);

#endif
