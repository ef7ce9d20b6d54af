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

int tcb_atlas_train_ckpt_save(const tcb_atlas_trainer *t, const tcb_sequence *seq,
                              uint64_t seed, double seconds, const char *path, tcb_error *err)
{
    int64_t ints[N_INTS];
    double reals[N_REALS];
    tcb_ckpt_settings s = settings_of(t, seq, seed, ints, reals);
    tcb_train_progress p = {.it = t->it, .adam_t = t->adam.t, .loss0 = t->loss0, .seconds = seconds};
    memcpy(p.rng, t->rng.s, sizeof p.rng);
    tcb_ckpt_array a[N_ARRAYS];
    arrays_of(t, a);
    return tcb_train_ckpt_write(path, MAGIC, &s, &p, a, N_ARRAYS, err);
}

int tcb_atlas_train_ckpt_load(tcb_atlas_trainer *t, const tcb_sequence *seq, uint64_t seed,
                              const char *path, double *seconds, tcb_error *err)
{
    int64_t ints[N_INTS];
    double reals[N_REALS];
    tcb_ckpt_settings want = settings_of(t, seq, seed, ints, reals);
    tcb_ckpt_array a[N_ARRAYS];
    arrays_of(t, a);
    tcb_train_progress p;
    int rc = tcb_train_ckpt_read(path, MAGIC, "an atlas training checkpoint", &want, ints[I_ITERATIONS], &p, a,
                                 N_ARRAYS, err);
    if (rc) return rc;
    memcpy(t->rng.s, p.rng, sizeof p.rng);
    t->it = p.it, t->adam.t = p.adam_t, t->loss0 = p.loss0;
    *seconds = p.seconds;
    return TCB_OK;
}
