#include "methods/cycle/train_ckpt.h"

#include "neural/train_ckpt.h"

static const char *const int_names[] = {"C",      "Z",     "H",          "L",     "sampling",     "batch",
                                        "iterations", "warmup", "knn_k", "knn_points", "delta", "input points",
                                        "frames", "pool_size", "parameter count", "sequence fingerprint"};
static const char *const real_names[] = {"lr"};

/* The checkpoint of t: its settings, weights, Adam's moments and the
 * batch-norm running statistics, and where it keeps its progress. The
 * trainer is written through the spec only by load. */
static tcb_ckpt_spec spec_of(tcb_cc_trainer *t, const tcb_sequence *seq, uint64_t seed)
{
    const tcb_cc_train_cfg *c = &t->cfg;
    const tcb_cc_dims *d = &t->net->d;
    size_t n = t->net->nparams;
    return (tcb_ckpt_spec){
        .magic = "TCBCCTR2", .what = "a cc training checkpoint",
        .n_ints = 16, .n_reals = 1, .n_arrays = 4, .int_names = int_names, .real_names = real_names,
        .ints = {d->C, d->Z, d->H, d->L, c->sampler.sampling, c->batch, c->iterations, c->warmup,
                 c->sampler.knn_k, c->sampler.knn_points, c->sampler.delta, t->N, seq->n_frames, seq->pool_size,
                 (int64_t)n, (int64_t)tcb_sequence_fingerprint(seq)},
        .reals = {c->lr},
        .seed = seed, .max_it = c->iterations,
        .arrays = {{t->net->params, n}, {t->adam.m, n}, {t->adam.v, n}, {t->net->buffers, t->net->nbuffers}},
        .state = {.it = &t->it, .rng = &t->rng, .adam = &t->adam, .loss0 = &t->loss0},
    };
}

int tcb_cc_train_ckpt_save(const tcb_cc_trainer *t, const tcb_sequence *seq, uint64_t seed, double seconds,
                           const char *path, tcb_error *err)
{
    tcb_ckpt_spec s = spec_of((tcb_cc_trainer *)t, seq, seed); /* read only here */
    return tcb_ckpt_spec_save(&s, seconds, path, err);
}

int tcb_cc_train_ckpt_load(tcb_cc_trainer *t, const tcb_sequence *seq, uint64_t seed, const char *path,
                           double *seconds, tcb_error *err)
{
    tcb_ckpt_spec s = spec_of(t, seq, seed);
    return tcb_ckpt_spec_load(&s, path, seconds, err);
}
