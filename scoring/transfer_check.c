/* A method's transfer checked before it is scored (scoring/scoring.h): the
 * points tcb/method.h promises, or a failed cell naming what was wrong.
 * A plug-in's bug must cost its own cell, not the run: a point beyond the
 * k-NN search's range once stopped every cell after it, and NaN points
 * were kept as a "diverged" result that a rerun never retried.
 *
 * The far clause is measured to the box of every frame's vertices, not to
 * the vertices themselves as `tcbench score` measures it: within one
 * diagonal of that box the two agree to the box's size, far below the
 * clause's hundred diagonals, and the box needs no nearest-neighbour search
 * per pair (the search cost quick.json's evaluations a quarter more). */
#include <math.h>
#include <stdlib.h>

#include "scoring/scoring.h"
#include "tcb/geometry.h"
#include "tcb/predictions.h"

static int by_value(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The median distance from the points to the box. */
static int median_box_distance(const double box[6], const float *p, int n, double *out, tcb_error *err)
{
    double *dist = malloc((size_t)n * sizeof *dist);
    if (!dist) return tcb_fail(err, TCB_ERR_NOMEM, "out of memory for %d points", n);
    for (int k = 0; k < n; k++) {
        double s = 0;
        for (int d = 0; d < 3; d++) {
            double x = p[3 * k + d], out_by = fmax(fmax(box[d] - x, x - box[3 + d]), 0);
            s += out_by * out_by;
        }
        dist[k] = sqrt(s);
    }
    qsort(dist, (size_t)n, sizeof *dist, by_value);
    *out = dist[n / 2];
    free(dist);
    return TCB_OK;
}

int tcb_transfer_check(const double box[6], const tcb_sequence *seq, int j, const float *moved, tcb_error *merr)
{
    int nv = seq->n_verts;
    for (int v = 0; v < nv; v++) {
        const float *p = moved + 3 * (size_t)v;
        if (!isfinite(p[0]) || !isfinite(p[1]) || !isfinite(p[2]))
            return tcb_fail(merr, TCB_ERR_INPUT, "returned a non-finite point (vertex %d: %g %g %g)", v, p[0], p[1],
                            p[2]);
        if (!(fabsf(p[0]) <= TCB_NN_COORD_MAX && fabsf(p[1]) <= TCB_NN_COORD_MAX && fabsf(p[2]) <= TCB_NN_COORD_MAX))
            return tcb_fail(merr, TCB_ERR_INPUT, "returned a point beyond ±%g (vertex %d: %g %g %g)",
                            (double)TCB_NN_COORD_MAX, v, p[0], p[1], p[2]);
    }
    double frame_box[6], median = 0;
    tcb_bbox(tcb_seq_frame(seq, j), (size_t)nv, frame_box);
    double diag = tcb_bbox_diag(frame_box); /* D of the wrong-frame rule */
    int rc = median_box_distance(box, moved, nv, &median, merr);
    if (rc || median <= TCB_FRAME_FAR * diag) return rc;
    return tcb_fail(merr, TCB_ERR_INPUT,
                    "returned points off the shape: the points lie a median %.3g box diagonals outside the "
                    "sequence's bounding box (more than %g): no points of the shape (vertex ids or another unit "
                    "written as coordinates?)",
                    median / diag, TCB_FRAME_FAR);
}
