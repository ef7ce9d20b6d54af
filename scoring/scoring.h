/* The face of scoring/ for the engine (harness/), costs/ and views/: one
 * prediction to numbers. A pair's prediction (a method's transfer, or what
 * a file held) is projected and scored by the one path every cell takes
 * (tcb_cell_score_pair), and a method's surface is checked against what
 * tcb/method.h promises before anything uses it. The prediction readers
 * and the wrong-frame rule a method may use too are tcb/predictions.h. Not
 * installed. */
#ifndef TCB_SCORING_H
#define TCB_SCORING_H

#include <stdint.h>

#include "tcb/geodesic.h"
#include "tcb/method.h"
#include "tcb/metrics.h"
#include "tcb/results.h"

/* What tcb/method.h promises of a method's surface of `frame` (at most
 * max_charts charts), checked before anything uses it; a failure lands in
 * merr (scoring/surface_check.c). */
int tcb_surface_check(const tcb_uv_mesh *m, int frame, int max_charts, tcb_error *merr);

/* What tcb/method.h promises of a transfer (frame i's vertices carried
 * onto frame j, moved[n_verts][3]), checked before anything scores it:
 * every coordinate finite and within ±TCB_NN_COORD_MAX (what the k-NN
 * search takes), and the points not a median TCB_FRAME_FAR diagonals of
 * frame j's box outside `box`, the box of every frame's vertices
 * (tcb_bbox of seq->verts; the wrong-frame rule's far clause;
 * its raw-coordinate clause is for files: a method is given normalised
 * frames). A violation is TCB_ERR_INPUT in merr, naming the vertex or
 * giving the median: the method's output is wrong, and its cell fails
 * (scoring/transfer_check.c). */
int tcb_transfer_check(const double box[6], const tcb_sequence *seq, int j, const float *moved, tcb_error *merr);

/* One evaluation pair's prediction: a method's transfer, or what `tcbench
 * score` read from a file. */
typedef struct tcb_pair_prediction {
    int i, j;                 /* frames: source, target */
    const float *moved;       /* [n_verts][3] frame i's vertices carried onto frame j; NULL
                               * when pred already holds the ids */
    int32_t *pred;            /* [n_verts] the predicted vertex of frame j per vertex; the
                               * projection of moved is written here */
    double cd;                /* the pair's Chamfer distance; NaN without reconstructions */
    double *geo;              /* [n_verts] out: each vertex's normalised geodesic error; NULL
                               * when not wanted */
} tcb_pair_prediction;

/* What scoring a sequence's pairs needs beside the predictions: the
 * sequence, and the edge graph of its faces for the geodesic error
 * (tcb/geodesic.h), made once for all pairs since every frame shares the
 * faces. (scoring/pair_score.c) */
typedef struct tcb_pair_scorer {
    const tcb_sequence *seq;
    tcb_edge_graph graph;
} tcb_pair_scorer;
int tcb_pair_scorer_init(tcb_pair_scorer *s, const tcb_sequence *seq, tcb_error *err);
void tcb_pair_scorer_free(tcb_pair_scorer *s);

/* The cell file's record of pair (i, j): its metrics (the geodesic ones
 * when m has them) and Chamfer distance (NaN: none). (scoring/pair_score.c) */
tcb_pair_record tcb_pair_record_of(int i, int j, const tcb_pair_metrics *m, double cd);

/* Scores one pair: moved (when given) projected onto frame j's nearest GT
 * vertices, the metrics, the geodesic error among them (into *pm; may be
 * NULL), the cell file's record into *rec, and the pair added to *sum. The
 * one path from a prediction to a cell's numbers, for methods' cells and
 * scored cells alike, so a metric added here reaches both.
 * (scoring/pair_score.c) */
int tcb_cell_score_pair(const tcb_pair_scorer *s, const tcb_pair_prediction *p, tcb_pair_record *rec,
                        tcb_summary *sum, tcb_pair_metrics *pm, tcb_error *err);

#endif
