/* Training checkpoints of cc (format neural/train_ckpt.h, magic
 * "TCBCCTR2"; TCBCCTR1 lacked the sequence's fingerprint): the settings below, the training's progress, and the
 * weights, Adam's moments and the batch-norm running statistics (params,
 * m, v: nparams floats each; buffers: nbuffers). Resuming with the same
 * thread count ends bit-identical to an uninterrupted training
 * (tests/unit/test_cc_train.c).
 *
 * Settings (int64): C, Z, H, L, sampling, batch, iterations, warmup,
 * knn_k, knn_points, delta, input points, frames, pool_size, parameter
 * count, the sequence's fingerprint (tcb_sequence_fingerprint); (double): lr; and the seed of the training stream. A checkpoint
 * of other settings is refused naming the first key that differs. */
#ifndef TCB_CC_TRAIN_CKPT_H
#define TCB_CC_TRAIN_CKPT_H

#include <stdint.h>

#include "methods/cycle/train.h"

/* The name of the checkpoint inside a cell's work directory. */
#define TCB_CC_TRAIN_CKPT "train.ckpt"

int tcb_cc_train_ckpt_save(const tcb_cc_trainer *t, const tcb_sequence *seq, uint64_t seed, double seconds,
                           const char *path, tcb_error *err);

/* Restores t (created with the same settings, network and sequence) from
 * the file, and *seconds from its time stamp; the refusals of
 * tcb_train_ckpt_read. On failure t and *seconds are unchanged. */
int tcb_cc_train_ckpt_load(tcb_cc_trainer *t, const tcb_sequence *seq, uint64_t seed, const char *path,
                           double *seconds, tcb_error *err);

#endif
