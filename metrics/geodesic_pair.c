/* The geodesic error of one pair (tcb/geodesic.h): shortest paths on frame
 * j's edge graph, normalised by sqrt(area_j), pooled like m_sL2, and its
 * PCK curve over [0, TCB_GEO_PCK_MAX]. */
#include "tcb/geodesic.h"

#include <math.h>
#include <stdlib.h>

int tcb_pair_geodesic_compute(const tcb_edge_graph *g, const float *verts_j, double area_j,
                              const int32_t *pred, tcb_pair_metrics *out, double *verr,
                              tcb_error *err)
{
    int nv = g->n_verts;
    if (nv < 1) return tcb_fail(err, TCB_ERR_INPUT, "geodesic: frame has no vertices");
    /* A zero or non-finite area has no normalisation; a loaded sequence
     * never has one (its pools are drawn by area), so this is bad input. */
    if (!(area_j > 0.0) || !isfinite(area_j))
        return tcb_fail(err, TCB_ERR_INPUT, "geodesic: frame area %g cannot normalise", area_j);
    double *w = malloc(((size_t)2 * g->n_edges + 1) * sizeof *w);
    double *own = verr ? NULL : malloc((size_t)nv * sizeof *own);
    double *e = verr ? verr : own;
    if (!w || !e) {
        free(w), free(own);
        return tcb_fail(err, TCB_ERR_NOMEM, "geodesic: out of memory for %d vertices", nv);
    }
    tcb_edge_graph_lengths(g, verts_j, w);
    int unreachable = 0;
    int rc = tcb_geodesic_to_pred(g, w, verts_j, pred, e, &unreachable, err);
    free(w);
    if (!rc) {
        double root = sqrt(area_j);
        out->geo = (tcb_stat){0};
        for (int k = 0; k < nv; k++) {
            e[k] /= root;
            tcb_stat_push(&out->geo, e[k]);
        }
        tcb_pck_curve(e, nv, tcb_geo_pck_threshold, TCB_GEO_PCK_STEPS, out->geo_pck,
                      &out->geo_auc);
        out->geo_unreachable = unreachable;
    }
    free(own);
    return rc;
}
