/* What the pcgrid methods do to a sequence's point clouds before they
 * optimise (github vc-bonn/neu-pig @ f5e1c1c: src/utilities/util.py
 * scale_points / scale, src/network/geometry_utils.py compute_keyframe, as
 * src/opt_run.py calls them; PDG @ cf21c7d the same, src/utilities/util.py
 * and src/opt_run.py, its keyframe lattice res 128, 512 for AMA).
 *
 * Normalisation: one box over every point of every frame; centred on the
 * box's centre, divided by half its largest side, times 0.95, so the
 * sequence fits the grids' cube [−1, 1]³ with a margin:
 *     p' = (p − c) · 0.95 / h,  c = (max + min) / 2,  h = max_k (max_k − min_k) / 2.
 *
 * Keyframe: the frame whose normalised points occupy the most cells of a
 * res³ lattice over [−1, 1]³ (cell ⌊(p' + 1)/2 · res⌋ per axis), weighted
 * towards the middle of the sequence by exp(−0.001 k²), k = t + ⌊−T/2⌋
 * (k from ⌊−T/2⌋ to ⌊T/2⌋ − 1, as Python's arange(-T // 2, T // 2)); the
 * first of equal maxima. Neu-PiG calls it with its default res 512. */
#ifndef TCB_PCGRID_PREPARE_H
#define TCB_PCGRID_PREPARE_H

#include "tcb/error.h"

#define TCB_PCGRID_MARGIN 0.95
#define TCB_PCGRID_KEYFRAME_RES 512

typedef struct tcb_pcgrid_frame_map {
    double centre[3];
    double scale; /* 0.95 / h: p' = (p − centre) · scale */
} tcb_pcgrid_frame_map;

/* The map of points [T] → [n[t]][3]; an error when there is no point, a
 * coordinate is not finite, or every point is the same. */
int tcb_pcgrid_frame_map_of(const float *const *points, const int *n, int T, tcb_pcgrid_frame_map *out,
                            tcb_error *err);

/* out [n][3] = the map applied to pts [n][3] (may alias). */
void tcb_pcgrid_map_points(const tcb_pcgrid_frame_map *m, const float *pts, int n, float *out);

/* Its inverse, in place: pts [n][3] of the cube back in the sequence's
 * coordinates (the read-out's points and the template's OBJ). */
void tcb_pcgrid_unmap_points(const tcb_pcgrid_frame_map *m, float *pts, int n);

/* The keyframe of normalised points [T] → [n[t]][3] on a res³ lattice. */
int tcb_pcgrid_keyframe(const float *const *points, const int *n, int T, int res, int *key, tcb_error *err);

#endif
