/* One training iteration of CC (the CC code's Trainer.train_iteration,
 * training/trainer.py; reference-protocol §3.6): B triplets of frames, a
 * fresh input cloud of each in its frame box, augmented; the network run
 * on the six ordered pairs of every triplet in the CC code's order (and,
 * during the warm-up, on the self-reconstruction pair (C, C') and (C', C));
 * Chamfer + cycle-2 + cycle-3 (+ self-reconstruction); backward; Adam with
 * the step lr, recreated at each decay as the CC code does.
 *
 * Batch norm. Each network call is one PyTorch forward: its batch norms
 * pool their statistics over that call's B shapes (× N points) and move
 * their running statistics once. The CC code computes a latent once and
 * reuses it across pairs (forward_chamfer with latent_P*) — here too, so an
 * encoder runs once per cloud in the pair calls; in the self-reconstruction
 * calls the CC code runs both encoders afresh, which for a cloud already
 * encoded gives the same output and moves the running statistics again
 * (tcb_cc_encoder_count_again). */
#ifndef TCB_CC_TRAIN_H
#define TCB_CC_TRAIN_H

#include <stdint.h>

#include "methods/cycle/augment.h"
#include "methods/cycle/deform.h"
#include "methods/cycle/encoder.h"
#include "methods/cycle/losses.h"
#include "methods/cycle/triplets.h"
#include "neural/adam.h"
#include "tcb/error.h"
#include "tcb/rng.h"
#include "tcb/sequence.h"

typedef struct tcb_cc_train_cfg {
    tcb_cc_sampler_opts sampler;
    int batch;            /* triplets per iteration (16), ≥ 2 for batch norm */
    long long iterations; /* total: lr ÷10 at 80 %, ÷100 at 90 % */
    long long warmup;     /* iterations with the self-reconstruction term (weight 1) */
    double lr;
    double divergence;    /* a loss above divergence × the first one stops training; 0: off */
} tcb_cc_train_cfg;

/* The network calls of one iteration: the six pairs, then the two
 * self-reconstruction calls. Clouds 0..2 are the triplet, 3 is C'. */
enum { TCB_CC_CALLS = 8, TCB_CC_CLOUDS = 4, TCB_CC_MAX_BATCH = 64 };

typedef struct tcb_cc_train_terms {
    tcb_cc_loss_terms cycle; /* chamfer, cycle2, cycle3 and their total */
    double selfrec;          /* ½(RMS(D(C, C') − C') + RMS(D(C', C) − C)); 0 after the warm-up */
    double total;
} tcb_cc_train_terms;

typedef struct tcb_cc_trainer {
    tcb_cc_train_cfg cfg;
    tcb_cc_net *net; /* borrowed */
    tcb_adam adam;
    tcb_rng rng;     /* triplets, clouds, augmentation */
    long long it;    /* iterations done */
    double loss0;    /* the loss of iteration 0 */
    tcb_cc_train_terms last;
    int N;           /* input points per cloud */
    int n_frames;
    tcb_cc_sampler *sampler;
    tcb_cc_frame_box *boxes;                  /* [n_frames] */
    tcb_cc_losses *losses;
    int frames[TCB_CC_CLOUDS - 1][TCB_CC_MAX_BATCH]; /* [cloud][b] the triplets' frames */
    float *clouds;                            /* [4][B][N][3] A, B, C, C' */
    float rot[TCB_CC_MAX_BATCH][9];           /* [b] C's augmentation rotation */
    tcb_cc_encoder_cache enc[2][TCB_CC_CLOUDS];
    int encoded[2][TCB_CC_CLOUDS];            /* enc[e][c] holds this iteration's forward */
    float *dz[2][TCB_CC_CLOUDS];              /* [B][Z] ∂L/∂z of enc[e][c] */
    tcb_cc_deform_cache dec[TCB_CC_CALLS];
    float *D, *gD;                            /* [8][B][N][3] outputs and their gradients */
    float *scratch;
} tcb_cc_trainer;

/* Trains `net` (already initialised) on seq, whose pools must be drawn;
 * clouds have seq->input_points points. The rng stream is (seed,
 * "cc/train"). */
int tcb_cc_trainer_create(const tcb_cc_train_cfg *cfg, tcb_cc_net *net, const tcb_sequence *seq,
                          uint64_t seed, tcb_cc_trainer **out, tcb_error *err);
void tcb_cc_trainer_free(tcb_cc_trainer *t);

/* Iteration t->it; *loss gets the total before the update (t->last its
 * terms). A non-finite loss or gradient, or a loss above cfg.divergence ×
 * the first iteration's, is TCB_ERR_NUMERIC naming the iteration; the
 * parameters are then left as they were before the step (the running
 * statistics are not: a diverged training is not continued). */
int tcb_cc_train_step(tcb_cc_trainer *t, const tcb_sequence *seq, double *loss, tcb_error *err);

#endif
