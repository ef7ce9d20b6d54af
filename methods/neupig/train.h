/* Neu-PiG's optimisation (github vc-bonn/neu-pig src/optimization.py
 * forward, configs/method/fit_.json): every step is one epoch over all
 * frames (full batch), Adam on the grids' preconditioned parameters with
 * the rate lr_grid·lr_growth^l for position level l (the normal grid at
 * lr_grid, its only level being level 0) and on the MLP at lr_mlp, no
 * schedule. The state is checkpointed through neural/train_ckpt.h and
 * continued bit-identically; a non-finite gradient or a loss beyond
 * divergence × the first epoch's ends the training (tcb_train_guard). */
#ifndef TCB_NEUPIG_TRAIN_H
#define TCB_NEUPIG_TRAIN_H

#include "methods/neupig/model.h"
#include "neural/adam.h"

typedef struct tcb_neupig_schedule {
    long long epochs;          /* 1 000 (the paper), 250 (its fast variant) */
    double lr_grid, lr_growth; /* 0.005, 2.5 */
    double lr_mlp;             /* 1e-3 */
    double divergence;         /* 0: no test */
} tcb_neupig_schedule;

typedef struct tcb_neupig_trainer {
    tcb_neupig_model model;
    tcb_neupig_schedule sched;
    const tcb_neupig_problem *problem; /* the caller's, for the trainer's life */
    float *params, *grads;             /* [model.n_params] */
    tcb_neupig_work work;              /* the epoch's buffers, for the problem's sizes */
    tcb_adam adam;
    size_t bounds[TCB_NEUPIG_MAX_LEVELS + 3]; /* Adam's groups: the grids, then the MLP */
    double lrs[TCB_NEUPIG_MAX_LEVELS + 2];
    long long it;                      /* epochs done */
    double loss0;
    tcb_rng rng;                       /* the initialisation's stream */
    tcb_neupig_loss last;              /* the last epoch's loss */
} tcb_neupig_trainer;

/* Parameters initialised from seed (tcb_neupig_params_init). */
int tcb_neupig_trainer_init(tcb_neupig_trainer *t, const tcb_neupig_arch *a,
                            const tcb_neupig_schedule *s, const tcb_neupig_problem *p, uint64_t seed,
                            tcb_error *err);
void tcb_neupig_trainer_free(tcb_neupig_trainer *t);

/* One epoch: loss and gradient at the current parameters, then Adam. */
int tcb_neupig_train_step(tcb_neupig_trainer *t, double *loss, tcb_error *err);

/* The whole training state; a checkpoint of other settings (architecture,
 * schedule, frames, template size, keyframe, seed) is refused. */
int tcb_neupig_train_save(const tcb_neupig_trainer *t, uint64_t seed, double seconds, const char *path,
                          tcb_error *err);
int tcb_neupig_train_load(tcb_neupig_trainer *t, uint64_t seed, const char *path, double *seconds,
                          tcb_error *err);

#endif
