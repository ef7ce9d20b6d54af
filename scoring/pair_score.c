/* The one path from a pair's prediction to a cell's numbers
 * (scoring/scoring.h): the projection onto frame j's GT vertices, the
 * paper's metrics, the geodesic error, the pair's record and the summary.
 * A method's cells (harness/cell.c) and scored cells (harness/score.c)
 * both come through here. */
#include <string.h>

#include "scoring/scoring.h"

int tcb_pair_scorer_init(tcb_pair_scorer *s, const tcb_sequence *seq, tcb_error *err)
{
    memset(s, 0, sizeof *s);
    s->seq = seq;
    if (!seq->n_faces) return TCB_OK; /* points alone: no geodesic error */
    int rc = tcb_edge_graph_build(seq->faces, seq->n_faces, seq->n_verts, &s->graph, err);
    if (rc) tcb_error_prefix(err, "%s: ", seq->name);
    return rc;
}

void tcb_pair_scorer_free(tcb_pair_scorer *s)
{
    tcb_edge_graph_free(&s->graph);
    s->seq = NULL;
}

tcb_pair_record tcb_pair_record_of(int i, int j, const tcb_pair_metrics *m, double cd)
{
    return (tcb_pair_record){i,  j,  m->sl2, m->sl2sq,   m->rank,
                             m->auc, cd, m->geo, m->geo_auc, m->geo_unreachable};
}

int tcb_cell_score_pair(const tcb_pair_scorer *s, const tcb_pair_prediction *p, tcb_pair_record *rec,
                        tcb_summary *sum, tcb_pair_metrics *pm, tcb_error *err)
{
    const tcb_sequence *seq = s->seq;
    const float *verts_j = tcb_seq_frame(seq, p->j);
    int nv = seq->n_verts;
    tcb_pair_metrics m;
    int rc = p->moved ? tcb_project_to_vertices(verts_j, nv, p->moved, nv, p->pred, err) : TCB_OK;
    if (!rc) rc = tcb_pair_metrics_compute(verts_j, nv, p->pred, &m, err);
    /* after the paper's metrics, which reset m */
    if (!rc && seq->n_faces)
        rc = tcb_pair_geodesic_compute(&s->graph, verts_j, seq->areas[p->j], p->pred, &m, p->geo, err);
    if (rc) return rc;
    *rec = tcb_pair_record_of(p->i, p->j, &m, p->cd);
    tcb_summary_add_pair(sum, &m, p->cd);
    if (pm) *pm = m;
    return TCB_OK;
}
