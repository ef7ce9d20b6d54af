/* Neu-PiG's optimisation loop step and its checkpoints (methods/neupig/train.h). */
#include "methods/neupig/train.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "neural/train_ckpt.h"
#include "neural/train_loop.h"

int tcb_neupig_trainer_init(tcb_neupig_trainer *t, const tcb_neupig_arch *a,
                            const tcb_neupig_schedule *s, const tcb_neupig_problem *p, uint64_t seed,
                            tcb_error *err)
{
    memset(t, 0, sizeof *t);
    if (s->epochs < 1 || !(s->lr_grid > 0) || !(s->lr_growth > 0) || !(s->lr_mlp > 0) || !(s->divergence >= 0))
        return tcb_fail(err, TCB_ERR_INPUT, "neupig: invalid schedule (epochs %lld, lr %g, %g, %g)",
                        s->epochs, s->lr_grid, s->lr_growth, s->lr_mlp);
    int rc = tcb_neupig_model_init(&t->model, a, err);
    if (rc) return rc;
    t->sched = *s;
    t->problem = p;
    size_t n = t->model.n_params;
    t->params = malloc(n * sizeof *t->params);
    t->grads = malloc(n * sizeof *t->grads);
    rc = t->params && t->grads ? tcb_adam_init(&t->adam, n, err)
                               : tcb_fail(err, TCB_ERR_NOMEM, "neupig: out of memory for %zu parameters", n);
    if (!rc) rc = tcb_neupig_work_init(&t->work, &t->model, p, err);
    if (rc) {
        tcb_neupig_trainer_free(t);
        return rc;
    }
    int grids = t->model.grids;
    for (int g = 0; g <= grids; g++) t->bounds[g] = t->model.grid_off[g];
    t->bounds[grids + 1] = n;
    for (int g = 0; g < grids; g++) t->lrs[g] = s->lr_grid * pow(s->lr_growth, g == a->levels ? 0 : g);
    t->lrs[grids] = s->lr_mlp;
    tcb_rng_seed_stream(&t->rng, seed, "neupig");
    tcb_neupig_params_init(&t->model, t->params, &t->rng);
    return TCB_OK;
}

void tcb_neupig_trainer_free(tcb_neupig_trainer *t)
{
    tcb_neupig_model_free(&t->model);
    tcb_adam_free(&t->adam);
    tcb_neupig_work_free(&t->work);
    free(t->params);
    free(t->grads);
    memset(t, 0, sizeof *t);
}

int tcb_neupig_train_step(tcb_neupig_trainer *t, double *loss, tcb_error *err)
{
    int rc = tcb_neupig_loss_grad(&t->model, t->params, t->problem, &t->work, t->it, t->sched.epochs,
                                  &t->last, t->grads, err);
    if (!rc) {
        *loss = t->last.total;
        rc = isfinite(*loss) ? tcb_train_guard("neupig", t->it, *loss, t->grads, t->model.n_params,
                                               t->sched.divergence, &t->loss0, err)
                             : tcb_fail(err, TCB_ERR_NUMERIC, "neupig: loss is %g", *loss);
    }
    if (rc) return rc;
    tcb_adam_step_groups(&t->adam, t->params, t->grads, t->bounds, t->lrs, t->model.grids + 1);
    t->it++;
    return TCB_OK;
}

static const char *const int_names[] = {"levels", "base_res", "res_step", "features", "normal_res",
                                        "normal_features", "time_freqs", "hidden", "epochs",
                                        "frames", "template vertices", "keyframe", "laplacian"};
static const char *const real_names[] = {"lambda", "lambda_growth", "normal_lambda", "edge_weight",
                                         "welsch_alpha", "lr_grid", "lr_growth", "lr_mlp"};

/* The checkpoint of t (written through only by load). */
static tcb_ckpt_spec spec_of(tcb_neupig_trainer *t, uint64_t seed)
{
    const tcb_neupig_arch *a = &t->model.a;
    const tcb_neupig_schedule *s = &t->sched;
    size_t n = t->model.n_params;
    return (tcb_ckpt_spec){
        .magic = "TCBNPIG2", .what = "a Neu-PiG training checkpoint",
        .n_ints = 13, .n_reals = 8, .n_arrays = 3, .int_names = int_names, .real_names = real_names,
        .ints = {a->levels, a->base_res, a->res_step, a->features, a->normal_res, a->normal_features,
                 a->time_freqs, a->hidden, s->epochs, t->problem->T, t->problem->nv, t->problem->key,
                 a->laplacian},
        .reals = {a->lambda, a->lambda_growth, a->normal_lambda, a->edge_weight, a->welsch_alpha,
                  s->lr_grid, s->lr_growth, s->lr_mlp},
        .seed = seed, .max_it = s->epochs,
        .arrays = {{t->params, n}, {t->adam.m, n}, {t->adam.v, n}},
        .state = {.it = &t->it, .rng = &t->rng, .adam = &t->adam, .loss0 = &t->loss0},
    };
}

int tcb_neupig_train_save(const tcb_neupig_trainer *t, uint64_t seed, double seconds, const char *path,
                          tcb_error *err)
{
    tcb_ckpt_spec s = spec_of((tcb_neupig_trainer *)t, seed); /* read only here */
    return tcb_ckpt_spec_save(&s, seconds, path, err);
}

int tcb_neupig_train_load(tcb_neupig_trainer *t, uint64_t seed, const char *path, double *seconds,
                          tcb_error *err)
{
    tcb_ckpt_spec s = spec_of(t, seed);
    return tcb_ckpt_spec_load(&s, path, seconds, err);
}
