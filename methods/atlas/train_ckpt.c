#include "methods/atlas/train_ckpt.h"

#include <string.h>

#include "neural/train_ckpt.h"

#define MAGIC "TCBATRN2"

enum { I_ITERATIONS = 5, N_INTS = 10, N_REALS = 3, N_ARRAYS = 3 };
static const char *const int_names[N_INTS] = {"latent", "patches", "uv_samples", "loss",
                                              "delta", "iterations", "input_points",
                                              "frames", "pool_size", "parameter count"};
static const char *const real_names[N_REALS] = {"lr", "alpha_mc", "alpha_sciso"};

/* The settings block (what must match for a checkpoint to be continued),
 * filled into caller-owned storage. */
static tcb_ckpt_settings settings_of(const tcb_atlas_trainer *t, const tcb_sequence *seq, uint64_t seed,
                                     int64_t ints[N_INTS], double reals[N_REALS])
{
    const tcb_atlas_train_cfg *c = &t->cfg;
    int64_t in[N_INTS] = {t->model->C, t->model->P, c->M, c->loss, c->delta, c->iterations, t->N,
                          seq->n_frames, seq->pool_size, (int64_t)t->model->nparams};
    double re[N_REALS] = {c->lr, c->alpha_mc, c->alpha_sciso};
    memcpy(ints, in, sizeof in);
    memcpy(reals, re, sizeof re);
    return (tcb_ckpt_settings){.n_ints = N_INTS, .n_reals = N_REALS, .int_names = int_names,
                               .real_names = real_names, .ints = ints, .reals = reals, .seed = seed};
}

/* The weights and Adam's moments, in file order. */
static void arrays_of(const tcb_atlas_trainer *t, tcb_ckpt_array a[N_ARRAYS])
{
    size_t n = t->model->nparams;
    a[0] = (tcb_ckpt_array){t->model->params, n};
    a[1] = (tcb_ckpt_array){t->adam.m, n};
    a[2] = (tcb_ckpt_array){t->adam.v, n};
}

/* The trainer's progress, where it keeps it. */
static tcb_trainer_state state_of(tcb_atlas_trainer *t)
{
    return (tcb_trainer_state){.it = &t->it, .rng = &t->rng, .adam = &t->adam, .loss0 = &t->loss0};
}

int tcb_atlas_train_ckpt_save(const tcb_atlas_trainer *t, const tcb_sequence *seq, uint64_t seed, double seconds,
                       const char *path, tcb_error *err)
{
    int64_t ints[N_INTS];
    double reals[N_REALS];
    tcb_ckpt_settings s = settings_of(t, seq, seed, ints, reals);
    tcb_ckpt_array a[N_ARRAYS];
    arrays_of(t, a);
    tcb_trainer_state st = state_of((tcb_atlas_trainer *)t); /* read only: the pointers are for load's sake */
    return tcb_trainer_state_save(path, MAGIC, &s, &st, seconds, a, N_ARRAYS, err);
}

int tcb_atlas_train_ckpt_load(tcb_atlas_trainer *t, const tcb_sequence *seq, uint64_t seed, const char *path,
                       double *seconds, tcb_error *err)
{
    int64_t ints[N_INTS];
    double reals[N_REALS];
    tcb_ckpt_settings want = settings_of(t, seq, seed, ints, reals);
    tcb_ckpt_array a[N_ARRAYS];
    arrays_of(t, a);
    tcb_trainer_state st = state_of(t);
    return tcb_trainer_state_load(path, MAGIC, "an atlas training checkpoint", &want, ints[I_ITERATIONS], &st, seconds, a, N_ARRAYS,
                                  err);
}
