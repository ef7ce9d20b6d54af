/* tcbench — how far a sequence's motion is from isometric.
 *
 * Articulated motion (a walk, a gallop) nearly preserves lengths measured
 * on the surface; a collapse, a deflation or a stretch does not, and that
 * is what the stress test's sequences are for. Per frame f against frame 0:
 *   edge_mean, edge_max  mean and max over the mesh's edges of |l_f / l_0 − 1|
 *   geo_mean             mean over (source, vertex) pairs of |g_f / g_0 − 1|,
 *                        g the shortest path on the edge graph (tcb/geodesic.h)
 *                        from TCB_DISTORTION_SOURCES sources spread over the
 *                        vertex ids to every vertex reachable from them
 *   area_ratio           surface area of f over that of frame 0
 * Edges of zero length in frame 0, and vertices at zero or infinite
 * geodesic distance from a source, are left out of the means. Any uniform
 * scale shows up as distortion: compare frames of one normalisation. */
#ifndef TCB_DISTORTION_H
#define TCB_DISTORTION_H

#include "tcb/error.h"
#include "tcb/sequence.h"

#ifdef __cplusplus
extern "C" {
#endif

#define TCB_DISTORTION_SOURCES 8

typedef struct tcb_distortion {
    double edge_mean, edge_max;
    double geo_mean;
    double area_ratio;
} tcb_distortion;

/* out[f] for every frame f of s (out [s->n_frames]; out[0] is all zeros
 * but area_ratio 1). */
int tcb_sequence_distortion(const tcb_sequence *s, tcb_distortion *out, tcb_error *err);

#ifdef __cplusplus
}
#endif
#endif
