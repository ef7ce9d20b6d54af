#include "methods/cycle/train_ckpt.h"

#include <string.h>

#include "neural/train_ckpt.h"

#define MAGIC "TCBCCTR1"

enum { I_ITERATIONS = 6, N_INTS = 15, N_REALS = 1, N_ARRAYS = 4 };
static const char *const int_names[N_INTS] = {"C", "Z", "H", "L", "sampling", "batch", "iterations",
                                              "warmup", "knn_k", "knn_points", "delta", "input points",
                                              "frames", "pool_size", "parameter count"};
static const char *const real_names[N_REALS] = {"lr"};

static tcb_ckpt_settings settings_of(const tcb_cc_trainer *t, const tcb_sequence *seq, uint64_t seed,
                                     int64_t ints[N_INTS], double reals[N_REALS])
{
    const tcb_cc_train_cfg *c = &t->cfg;
    const tcb_cc_dims *d = &t->net->d;
    int64_t in[N_INTS] = {d->C, d->Z, d->H, d->L, c->sampler.sampling, c->batch, c->iterations, c->warmup,
                          c->sampler.knn_k, c->sampler.knn_points, c->sampler.delta, t->N, seq->n_frames,
                          seq->pool_size, (int64_t)t->net->nparams};
    memcpy(ints, in, sizeof in);
    reals[0] = c->lr;
    return (tcb_ckpt_settings){.n_ints = N_INTS, .n_reals = N_REALS, .int_names = int_names,
                               .real_names = real_names, .ints = ints, .reals = reals, .seed = seed};
}

static void arrays_of(const tcb_cc_trainer *t, tcb_ckpt_array a[N_ARRAYS])
{
    size_t n = t->net->nparams;
    a[0] = (tcb_ckpt_array){t->net->params, n};
    a[1] = (tcb_ckpt_array){t->adam.m, n};
    a[2] = (tcb_ckpt_array){t->adam.v, n};
    a[3] = (tcb_ckpt_array){t->net->buffers, t->net->nbuffers};
}

/* The trainer's progress, where it keeps it. */
static tcb_trainer_state state_of(tcb_cc_trainer *t)
{
    return (tcb_trainer_state){.it = &t->it, .rng = &t->rng, .adam = &t->adam, .loss0 = &t->loss0};
}

int tcb_cc_train_ckpt_save(const tcb_cc_trainer *t, const tcb_sequence *seq, uint64_t seed, double seconds,
                       const char *path, tcb_error *err)
{
    int64_t ints[N_INTS];
    double reals[N_REALS];
    tcb_ckpt_settings s = settings_of(t, seq, seed, ints, reals);
    tcb_ckpt_array a[N_ARRAYS];
    arrays_of(t, a);
    tcb_trainer_state st = state_of((tcb_cc_trainer *)t); /* read only: the pointers are for load's sake */
    return tcb_trainer_state_save(path, MAGIC, &s, &st, seconds, a, N_ARRAYS, err);
}

int tcb_cc_train_ckpt_load(tcb_cc_trainer *t, const tcb_sequence *seq, uint64_t seed, const char *path,
                       double *seconds, tcb_error *err)
{
    int64_t ints[N_INTS];
    double reals[N_REALS];
    tcb_ckpt_settings want = settings_of(t, seq, seed, ints, reals);
    tcb_ckpt_array a[N_ARRAYS];
    arrays_of(t, a);
    tcb_trainer_state st = state_of(t);
    return tcb_trainer_state_load(path, MAGIC, "a cc training checkpoint", &want, ints[I_ITERATIONS], &st, seconds, a, N_ARRAYS,
                                  err);
}
