/* One training iteration of the atlas family (reference-protocol §4):
 * a batch of two neighbour pairs [a1, b1, a2, b2], fresh input clouds and
 * fresh UV samples, the method's loss, backward, Adam with the step lr. */
#ifndef TCB_ATLAS_TRAIN_H
#define TCB_ATLAS_TRAIN_H

#include <stdint.h>

#include "methods/atlas/model.h"
#include "neural/adam.h"
#include "tcb/error.h"
#include "tcb/rng.h"
#include "tcb/sequence.h"
#include "tcb/split.h"

/* The three methods differ only here. */
typedef enum tcb_atlas_loss {
    TCB_ATLAS_LOSS_CHAMFER, /* atlasnet: L_CD, no tangents */
    TCB_ATLAS_LOSS_DSR,     /* dsr: L_CD + α_sciso L_sciso */
    TCB_ATLAS_LOSS_METRIC   /* mca: L_CD + α_mc L_mc */
} tcb_atlas_loss;

typedef struct tcb_atlas_train_cfg {
    tcb_atlas_loss loss;
    int M;                  /* UV samples per shape and iteration, a multiple of P */
    long long iterations;   /* total, for the lr schedule */
    double lr, alpha_mc, alpha_sciso;
    tcb_pair_mode pairs;    /* NEIGHBORS (1 ≤ |a − b| ≤ delta, the paper's) or RANDOM
                             * (b uniform over the other frames: Table 2) */
    int delta;
    double divergence;      /* a loss above divergence × the first one stops training */
} tcb_atlas_train_cfg;

#define TCB_ATLAS_BATCH 4 /* two pairs */

typedef struct tcb_atlas_trainer {
    tcb_atlas_train_cfg cfg;
    tcb_atlas_model *model; /* borrowed */
    tcb_atlas_work *work;
    tcb_adam adam;
    tcb_rng rng;            /* pairs, clouds and UV samples */
    long long it;           /* iterations done */
    double loss0;           /* the loss of iteration 0 */
    int N;                  /* input points per cloud */
    int frames[TCB_ATLAS_BATCH];
    double area[TCB_ATLAS_BATCH];
    float *clouds;                  /* [4][N][3] */
    float *uv;                      /* [M][2] */
    float *phi, *phi_u, *phi_v;     /* [4][M][3] */
    float *dphi, *dphi_u, *dphi_v;  /* [4][M][3] */
} tcb_atlas_trainer;

/* Trains `model` (already initialised) on seq, whose pools must be drawn;
 * clouds have seq->input_points points. The rng stream is
 * (seed, "atlas/train"). */
int tcb_atlas_trainer_create(const tcb_atlas_train_cfg *cfg, tcb_atlas_model *model,
                             const tcb_sequence *seq, uint64_t seed, tcb_atlas_trainer **out,
                             tcb_error *err);
void tcb_atlas_trainer_free(tcb_atlas_trainer *t);

/* Iteration t->it: *loss gets the total loss before the update. A
 * non-finite loss or gradient, or a loss above cfg.divergence × the first
 * iteration's, is TCB_ERR_NUMERIC naming the iteration (the harness records
 * the cell as diverged); the parameters are then left as they were before
 * the step. */
int tcb_atlas_train_step(tcb_atlas_trainer *t, const tcb_sequence *seq, double *loss,
                         tcb_error *err);

#endif
