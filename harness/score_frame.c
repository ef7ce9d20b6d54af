/* The wrong-frame rule for point predictions (tcb/score.h,
 * docs/formats.md): predicted points that mostly lie far outside the
 * target frame's extent were computed in another frame (the dataset's raw
 * coordinates most often), and scoring them would report a number about
 * the frame, not about the method.
 *
 * The rule: with B the axis-aligned bounding box of frame j's vertices and
 * D its diagonal, the points are refused when more than half of them lie
 * farther than TCB_FRAME_TOLERANCE * D from B (their median distance to B
 * exceeds it). The median, not the mean or the farthest point: a method
 * that diverged on some vertices (points flung anywhere) still has most of
 * them on the shape, and its bad numbers are the method's to report. Half
 * a diagonal outside the box is farther than any limb moves between two
 * frames of a sequence, in the box of the target frame itself, so a real
 * transfer's points, however wrong their correspondence, are never that far.
 * Raw coordinates are refused whenever the normalisation moves the
 * shape's box by more than that (a shift or a scale change of the order of
 * the shape's own size: both the synthetic sequences, in metres with their
 * first frame centred, and the cat, in centimetres, are). */
#include <math.h>
#include <stdio.h>

#include "tcb/score.h"

static void box_of(const float *p, int n, double lo[3], double hi[3])
{
    for (int d = 0; d < 3; d++) lo[d] = INFINITY, hi[d] = -INFINITY;
    for (int k = 0; k < n; k++)
        for (int d = 0; d < 3; d++) {
            lo[d] = fmin(lo[d], p[3 * k + d]);
            hi[d] = fmax(hi[d], p[3 * k + d]);
        }
}

/* Distance from point p to the box [lo, hi] (0 inside). */
static double box_distance(const float *p, const double lo[3], const double hi[3])
{
    double s = 0;
    for (int d = 0; d < 3; d++) {
        double out = fmax(fmax(lo[d] - p[d], p[d] - hi[d]), 0.0);
        s += out * out;
    }
    return sqrt(s);
}

int tcb_score_check_frame(const float *verts_j, int nv, const float *points, int n, tcb_error *err)
{
    double lo[3], hi[3], plo[3], phi[3];
    box_of(verts_j, nv, lo, hi);
    double diag = sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                       (hi[2] - lo[2]) * (hi[2] - lo[2]));
    int far = 0;
    for (int k = 0; k < n; k++) far += box_distance(points + 3 * (size_t)k, lo, hi) > TCB_FRAME_TOLERANCE * diag;
    if (2 * (long)far <= n) return TCB_OK;
    box_of(points, n, plo, phi);
    return tcb_fail(err, TCB_ERR_INPUT,
                    "%d of %d points lie farther than %g box diagonals from the target frame (its box [%.3g, %.3g, %.3g] "
                    "to [%.3g, %.3g, %.3g], the points' [%.3g, %.3g, %.3g] to [%.3g, %.3g, %.3g]): points in another frame?",
                    far, n, TCB_FRAME_TOLERANCE, lo[0], lo[1], lo[2], hi[0], hi[1], hi[2], plo[0], plo[1], plo[2],
                    phi[0], phi[1], phi[2]);
}
