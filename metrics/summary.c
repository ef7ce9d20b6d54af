/* Aggregation of pair metrics into a cell summary (reference-protocol §5.5):
 * sL2, sL2² and rank pooled over every vertex of every pair, AUC and CD over
 * pairs, the PCK curve averaged over pairs; the geodesic error likewise.
 * Summaries merge, so cells of several seeds, or runs split over machines,
 * pool exactly as one would. */
#include "tcb/metrics.h"

#include <math.h>

void tcb_summary_init(tcb_summary *s) { *s = (tcb_summary){0}; }

/* The geodesic part: its own pair count (geo_auc.n), since a summary of
 * an older cell has none and must not dilute the curve of one that has. */
static void merge_geodesic(tcb_summary *into, const tcb_summary *other)
{
    if (other->geo_auc.n == 0) return;
    double w = other->geo_auc.n / (into->geo_auc.n + other->geo_auc.n);
    for (int s = 0; s < TCB_GEO_PCK_STEPS; s++)
        into->geo_pck[s] += (other->geo_pck[s] - into->geo_pck[s]) * w;
    tcb_stat_merge(&into->geo, &other->geo);
    tcb_stat_merge(&into->geo_auc, &other->geo_auc);
    into->geo_unreachable += other->geo_unreachable;
}

void tcb_summary_merge(tcb_summary *into, const tcb_summary *other)
{
    tcb_stat_merge(&into->corr, &other->corr); /* clips: a cell may have them without pairs */
    tcb_stat_merge(&into->corr_mesh, &other->corr_mesh);
    for (int m = 0; m < TCB_N_RECON; m++) tcb_stat_merge(&into->recon[m], &other->recon[m]); /* over frames */
    if (other->n_pairs == 0) return;
    int n = into->n_pairs + other->n_pairs;
    double w = (double)other->n_pairs / n;
    for (int s = 0; s < TCB_PCK_STEPS; s++) into->pck[s] += (other->pck[s] - into->pck[s]) * w;
    tcb_stat_merge(&into->sl2, &other->sl2);
    tcb_stat_merge(&into->sl2sq, &other->sl2sq);
    tcb_stat_merge(&into->rank, &other->rank);
    tcb_stat_merge(&into->auc, &other->auc);
    tcb_stat_merge(&into->cd, &other->cd);
    merge_geodesic(into, other);
    into->n_pairs = n;
}

void tcb_summary_add_pair(tcb_summary *s, const tcb_pair_metrics *m, double cd)
{
    tcb_summary one = {.n_pairs = 1, .sl2 = m->sl2, .sl2sq = m->sl2sq, .rank = m->rank};
    tcb_stat_push(&one.auc, m->auc);
    if (!isnan(cd)) tcb_stat_push(&one.cd, cd);
    for (int i = 0; i < TCB_PCK_STEPS; i++) one.pck[i] = m->pck[i];
    if (m->geo.n > 0) {
        one.geo = m->geo;
        tcb_stat_push(&one.geo_auc, m->geo_auc);
        for (int i = 0; i < TCB_GEO_PCK_STEPS; i++) one.geo_pck[i] = m->geo_pck[i];
        one.geo_unreachable = m->geo_unreachable;
    }
    tcb_summary_merge(s, &one);
}
