/* The fit loop every trained method runs (the atlas family, cc): resume
 * from the cell's training checkpoint when there is one, step to the last
 * iteration with a progress bar and a debug line with the mean loss every
 * 1 000 iterations (a tenth of a shorter training),
 * save the training state every `checkpoint_every` iterations (and when
 * ctx asks it to stop: then it returns TCB_ERR_INTERRUPTED), and delete
 * it at the end (the harness's model checkpoint supersedes it). A
 * checkpoint that cannot be continued (corrupt, other settings) is reported
 * and ignored: training starts over, as the harness does with a bad model
 * checkpoint. The method supplies the trainer behind four callbacks. */
#ifndef TCB_NEURAL_TRAIN_LOOP_H
#define TCB_NEURAL_TRAIN_LOOP_H

#include "tcb/method.h"

typedef struct tcb_train_loop {
    const char *name;           /* the method's, for messages and the bar */
    long long iterations;       /* the last iteration */
    long long checkpoint_every; /* 0: no training checkpoints */
    const char *ckpt_name;      /* the file's name inside ctx->work_dir */
    void *trainer;
    /* One iteration; *loss its loss. */
    int (*step)(void *trainer, double *loss, tcb_error *err);
    /* Iterations done. */
    long long (*done)(const void *trainer);
    /* Writes / restores the whole training state; `seconds` is the training
     * time it has cost, over every process. */
    int (*save)(const void *trainer, double seconds, const char *path, tcb_error *err);
    int (*load)(void *trainer, const char *path, double *seconds, tcb_error *err);
} tcb_train_loop;

/* What every trainer checks after computing a step's loss and gradient,
 * before it updates: the gradient is finite, the first iteration's loss is
 * remembered (*loss0 at it = 0), and a loss beyond divergence × *loss0
 * (divergence > 0) is a divergence. Errors (TCB_ERR_NUMERIC, "iteration N:
 * NAME: non-finite gradient" / "… diverged, loss …") end the cell as
 * diverged. */
int tcb_train_guard(const char *name, long long it, double loss, const float *grads, size_t n,
                    double divergence, double *loss0, tcb_error *err);

/* Runs the loop with ctx->n_threads OpenMP threads (OpenBLAS's OpenMP
 * build follows them; the caller's setting is restored afterwards) and sets
 * *ctx->resumed_fit_s to the seconds a resumed checkpoint had cost. Errors
 * are prefixed with the method's name. */
int tcb_train_loop_run(const tcb_train_loop *loop, const tcb_fit_ctx *ctx, tcb_error *err);

#endif
