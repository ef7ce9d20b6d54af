/* Training checkpoints of the trained methods (the atlas family, cc):
 * everything a killed training needs to continue as if it had never stopped
 * — its settings, its progress (iteration, random stream, Adam's step
 * count, the first loss, the seconds spent) and its float arrays (weights,
 * Adam's moments, batch-norm running statistics) — in one file per
 * training. A method names its settings and arrays; this file owns the
 * format, the checksum and the refusals, so every method's checkpoints are
 * refused for the same reasons with the same words.
 *
 * File layout (host byte order; written atomically, so a reader sees the
 * previous checkpoint or the new one, never a mixture):
 *     char    magic[8]       the method's format, e.g. "TCBATRN2"
 *     int64   ints[n_ints]   integer settings
 *     double  reals[n_reals] real settings
 *     uint64  seed           of the training stream
 *     tcb_train_progress     (below: 9 × 8 bytes)
 *     float   arrays         each array in order, its n floats
 *     uint64  checksum       FNV-1a 64 of every byte before it
 * The settings are the fingerprint: a checkpoint of other settings (another
 * preset, another sequence) is refused with the first one that differs, so
 * a stale file is never silently continued. */
#ifndef TCB_NEURAL_TRAIN_CKPT_H
#define TCB_NEURAL_TRAIN_CKPT_H

#include <stddef.h>
#include <stdint.h>

#include "neural/adam.h"
#include "tcb/error.h"
#include "tcb/rng.h"

/* Where a training is. */
typedef struct tcb_train_progress {
    int64_t it;       /* iterations done */
    uint64_t rng[4];  /* the trainer's xoshiro state after iteration it */
    int64_t adam_t;   /* Adam's step count */
    double loss0;     /* the first iteration's loss (divergence test) */
    double seconds;   /* wall seconds of training up to iteration it, over
                       * every process that worked on it */
} tcb_train_progress;

/* What must match for a checkpoint to be continued; names for messages. */
typedef struct tcb_ckpt_settings {
    int n_ints, n_reals;
    const char *const *int_names;  /* [n_ints] */
    const char *const *real_names; /* [n_reals] */
    const int64_t *ints;           /* [n_ints] */
    const double *reals;           /* [n_reals] */
    uint64_t seed;
} tcb_ckpt_settings;

/* A float array saved and restored in place. */
typedef struct tcb_ckpt_array {
    float *data;
    size_t n;
} tcb_ckpt_array;

int tcb_train_ckpt_write(const char *path, const char magic[8], const tcb_ckpt_settings *s,
                         const tcb_train_progress *p, const tcb_ckpt_array *arrays, int n_arrays,
                         tcb_error *err);

/* Restores *p and the arrays from the file, all or nothing. TCB_ERR_INPUT
 * names the file and the reason: "bad magic" (another format, or another
 * version of this one), "truncated", "checksum mismatch", "made by another
 * training: <the first setting that differs>", an iteration outside
 * 0..max_it or a time that is "not a duration". On failure *p and the
 * arrays are unchanged. `what` names the kind of checkpoint in the bad-magic
 * message ("atlas training checkpoint"). */
int tcb_train_ckpt_read(const char *path, const char magic[8], const char *what,
                        const tcb_ckpt_settings *want, int64_t max_it, tcb_train_progress *p,
                        const tcb_ckpt_array *arrays, int n_arrays, tcb_error *err);

/* A trainer's progress where it keeps it, so that one call saves or
 * restores it: the iteration, the random stream (NULL for a training that
 * draws nothing after its start), Adam (its step count; the moments go in
 * as arrays) and the first loss. */
typedef struct tcb_trainer_state {
    long long *it;
    tcb_rng *rng;
    tcb_adam *adam;
    double *loss0;
} tcb_trainer_state;

#define TCB_CKPT_MAX_INTS 32
#define TCB_CKPT_MAX_REALS 8
#define TCB_CKPT_MAX_ARRAYS 8

/* Everything a method's checkpoint is, filled by the method (its settings'
 * values and names, its arrays, where its trainer keeps its progress), so
 * that saving and loading are one call each. */
typedef struct tcb_ckpt_spec {
    const char *magic;             /* 8 characters, e.g. "TCBATRN2" */
    const char *what;              /* for the bad-magic message: "an atlas training checkpoint" */
    int n_ints, n_reals, n_arrays;
    const char *const *int_names;  /* [n_ints] */
    const char *const *real_names; /* [n_reals] */
    int64_t ints[TCB_CKPT_MAX_INTS];
    double reals[TCB_CKPT_MAX_REALS];
    uint64_t seed;
    int64_t max_it;                /* the training's last iteration */
    tcb_ckpt_array arrays[TCB_CKPT_MAX_ARRAYS];
    tcb_trainer_state state;
} tcb_ckpt_spec;

/* tcb_train_ckpt_write of the spec's progress with `seconds` of training. */
int tcb_ckpt_spec_save(const tcb_ckpt_spec *s, double seconds, const char *path, tcb_error *err);

/* tcb_train_ckpt_read into the spec's arrays and progress (all or
 * nothing), *seconds its time stamp. */
int tcb_ckpt_spec_load(const tcb_ckpt_spec *s, const char *path, double *seconds, tcb_error *err);

#endif
