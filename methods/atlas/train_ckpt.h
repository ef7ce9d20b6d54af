/* Training checkpoints of the atlas family: everything a killed training
 * needs to continue as if it had never stopped — the weights, Adam's
 * moments and step count, the trainer's random stream and the iteration —
 * and the wall seconds the training had cost when it was written, so a
 * resumed fit reports its whole time.
 * Resuming with the same thread count ends bit-identical to an
 * uninterrupted training (tests/unit/test_atlas_ckpt.c).
 *
 * File layout (host byte order; written atomically, so a reader sees the
 * previous checkpoint or the new one, never a mixture):
 *     char    magic[8]    "TCBATRN2"
 *     int64   C, P, M, loss, delta, iterations, N, n_frames, pool_size, nparams
 *     double  lr, alpha_mc, alpha_sciso
 *     uint64  seed        of the training stream
 *     int64   it          iterations done
 *     uint64  rng[4]      the trainer's xoshiro state after iteration it
 *     int64   adam_t
 *     double  loss0       the first iteration's loss (divergence test)
 *     double  seconds     wall seconds of training up to iteration it, over
 *                         every process that worked on it
 *     float   params[nparams], m[nparams], v[nparams]
 *     uint64  checksum    FNV-1a 64 of every byte before it
 * The settings block is the fingerprint: a checkpoint of other settings
 * (another preset, another sequence) is refused with the first key that
 * differs, so a stale file is never silently continued. */
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
