/* Training checkpoints of the atlas family (format neural/train_ckpt.h,
 * magic "TCBATRN4"; TCBATRN3 lacked the sequence's fingerprint, TCBATRN2
 * the pairs mode): the settings below, the training's progress, and the
 * weights and Adam's moments (params, m, v: nparams floats each).
 * Resuming with the same thread count ends bit-identical to an
 * uninterrupted training (tests/unit/test_atlas_ckpt.c).
 *
 * Settings (int64): latent C, patches P, uv_samples M, loss, delta,
 * iterations, input_points N, frames, pool_size, parameter count, pairs,
 * the sequence's fingerprint (tcb_sequence_fingerprint: another sequence of
 * the same sizes is another training);
 * (double): lr, alpha_mc, alpha_sciso; and the seed of the training
 * stream. A checkpoint of other settings is refused naming the first key
 * that differs. */
#ifndef TCB_ATLAS_TRAIN_CKPT_H
#define TCB_ATLAS_TRAIN_CKPT_H

#include <stdint.h>

#include "methods/atlas/train.h"

/* The name of the checkpoint inside a cell's work directory. */
#define TCB_ATLAS_TRAIN_CKPT "train.ckpt"

int tcb_atlas_train_ckpt_save(const tcb_atlas_trainer *t, const tcb_sequence *seq,
                              uint64_t seed, double seconds, const char *path, tcb_error *err);

/* Restores t (created with the same settings, model and sequence) from the
 * file, and *seconds from its time stamp. TCB_ERR_INPUT names the file and
 * the reason: bad magic, truncated, checksum mismatch, the first setting
 * that differs, an iteration out of range or a time that is not a duration.
 * On failure t and *seconds are unchanged. */
int tcb_atlas_train_ckpt_load(tcb_atlas_trainer *t, const tcb_sequence *seq, uint64_t seed,
                              const char *path, double *seconds, tcb_error *err);

#endif
