/* tcbench — yaw alignment of a centred sequence (AMA, paper §4.2: "the
 * rotation along the vertical axis which minimizes the chamfer distance
 * w.r.t. the previous frame"; reference-protocol §1.3).
 *
 * The authors load precomputed per-frame rotations (rots_120.npy) and never
 * released them nor the script that makes them; this is the algorithm the
 * protocol infers from the file's name and the paper's sentence. Frame 0
 * keeps its orientation. For t ≥ 1, each of the 120 yaw angles k·3° about
 * the up axis y is tried on the centred frame t, and the one minimising the
 * symmetric Chamfer distance to the already aligned frame t−1 is kept, so
 * the rotations accumulate along the sequence. The distance is computed on
 * a fixed, seeded subset of the vertices (`samples` of them, the same ids
 * in every frame), not on all of them, so a sequence aligns in seconds.
 *
 * Rotation about y by θ: (x, y, z) → (x cos θ + z sin θ, y, −x sin θ + z cos θ). */
#ifndef TCB_ALIGN_H
#define TCB_ALIGN_H

#include <stdint.h>

#include "tcb/error.h"
#include "tcb/sequence.h"

#ifdef __cplusplus
extern "C" {
#endif

#define TCB_ALIGN_STEPS 120             /* candidate yaws: k · 360° / 120 */
#define TCB_ALIGN_DEFAULT_SAMPLES 1000  /* points per frame for the Chamfer (docs/protocol.md D4) */

/* The chosen yaw of every frame of s (whose vertices are centred, as
 * TCB_NORM_PER_FRAME leaves them): step[f] in 0..TCB_ALIGN_STEPS−1 (the
 * yaw is step · 360° / TCB_ALIGN_STEPS), step[0] = 0; chamfer[f] (NULL:
 * not wanted) the symmetric Chamfer of frame f, rotated, to the aligned
 * frame f−1 on the subset (mean squared distance each way, summed;
 * chamfer[0] = 0). The subset: `samples` distinct vertex ids drawn from
 * (seed, "align/<name>") by a partial Fisher–Yates shuffle (every vertex
 * when samples ≥ n_verts). Ties go to the smaller step. */
int tcb_align_yaw(const tcb_sequence *s, int samples, uint64_t seed, int *step, double *chamfer,
                  tcb_error *err);

/* The subset: ids[0..n) of the returned n = min(samples, n_verts), with
 * ids [n_verts] (the rest of the permutation follows). */
int tcb_align_vertex_ids(const tcb_sequence *s, int samples, uint64_t seed, int32_t *ids);

/* Rotates frame f's vertices by step[f] about y and records the yaws
 * (s->yaw, radians). Before the pools are sampled (they are drawn from the
 * rotated surfaces); areas are unchanged. */
int tcb_sequence_apply_yaw(tcb_sequence *s, const int *step, tcb_error *err);

/* The yaw of a step, in radians. */
double tcb_align_step_radians(int step);

#ifdef __cplusplus
}
#endif
#endif
