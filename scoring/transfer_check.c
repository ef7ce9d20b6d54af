/* A method's transfer checked before it is scored (scoring/scoring.h): the
 * points tcb/method.h promises, or a failed cell naming what was wrong.
 * A plug-in's bug must cost its own cell, not the run: a point beyond the
 * k-NN search's range once stopped every cell after it, and NaN points
 * were kept as a "diverged" result that a rerun never retried. */
#include <math.h>

#include "scoring/scoring.h"
#include "tcb/predictions.h"

int tcb_transfer_check(const tcb_nn *shape, const tcb_sequence *seq, int j, const float *moved, tcb_error *merr)
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
    int rc = tcb_score_check_shape(shape, tcb_seq_frame(seq, j), nv, moved, nv, merr);
    if (rc == TCB_ERR_INPUT) tcb_error_prefix(merr, "returned points off the shape: ");
    return rc;
}
