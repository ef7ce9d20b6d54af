#include "methods/atlas/train_ckpt.h"

#include "neural/train_ckpt.h"

static const char *const int_names[] = {"latent",     "patches",      "uv_samples", "loss",
                                        "delta",      "iterations",   "input_points", "frames",
                                        "pool_size",  "parameter count", "pairs",
                                        "sequence fingerprint"};
static const char *const real_names[] = {"lr", "alpha_mc", "alpha_sciso"};

/* The checkpoint of t: its settings, weights and Adam's moments, and where
 * it keeps its progress. The trainer is written through the spec only by
 * load. */
static tcb_ckpt_spec spec_of(tcb_atlas_trainer *t, const tcb_sequence *seq, uint64_t seed)
{
    const tcb_atlas_train_cfg *c = &t->cfg;
    size_t n = t->model->nparams;
    return (tcb_ckpt_spec){
        .magic = "TCBATRN4", .what = "an atlas training checkpoint",
        .n_ints = 12, .n_reals = 3, .n_arrays = 3, .int_names = int_names, .real_names = real_names,
        .ints = {t->model->C, t->model->P, c->M, c->loss, c->delta, c->iterations, t->N, seq->n_frames,
                 seq->pool_size, (int64_t)n, c->pairs, (int64_t)tcb_sequence_fingerprint(seq)},
        .reals = {c->lr, c->alpha_mc, c->alpha_sciso},
        .seed = seed, .max_it = c->iterations,
        .arrays = {{t->model->params, n}, {t->adam.m, n}, {t->adam.v, n}},
        .state = {.it = &t->it, .rng = &t->rng, .adam = &t->adam, .loss0 = &t->loss0},
    };
}

int tcb_atlas_train_ckpt_save(const tcb_atlas_trainer *t, const tcb_sequence *seq, uint64_t seed,
                              double seconds, const char *path, tcb_error *err)
{
    tcb_ckpt_spec s = spec_of((tcb_atlas_trainer *)t, seq, seed); /* read only here */
    return tcb_ckpt_spec_save(&s, seconds, path, err);
}

int tcb_atlas_train_ckpt_load(tcb_atlas_trainer *t, const tcb_sequence *seq, uint64_t seed,
                              const char *path, double *seconds, tcb_error *err)
{
    tcb_ckpt_spec s = spec_of(t, seq, seed);
    return tcb_ckpt_spec_load(&s, path, seconds, err);
}
