#include "methods/atlas/train.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "methods/atlas/loss_chamfer.h"
#include "methods/atlas/loss_dsr.h"
#include "methods/atlas/loss_metric.h"
#include "neural/train_loop.h"
#include "tcb/split.h"

static int uses_tangents(const tcb_atlas_train_cfg *c) { return c->loss != TCB_ATLAS_LOSS_CHAMFER; }

int tcb_atlas_trainer_create(const tcb_atlas_train_cfg *cfg, tcb_atlas_model *model,
                             const tcb_sequence *seq, uint64_t seed, tcb_atlas_trainer **out,
                             tcb_error *err)
{
    *out = NULL;
    if (seq->n_frames < 2 || seq->pool_size < 1 || seq->input_points < 1)
        return tcb_fail(err, TCB_ERR_INPUT,
                        "atlas: sequence %s needs at least 2 frames, point pools and input_points > 0 "
                        "(has %d frames, pool %d, input_points %d)",
                        seq->name, seq->n_frames, seq->pool_size, seq->input_points);
    if (cfg->M < model->P || cfg->M % model->P || cfg->delta < 1 || cfg->iterations < 1 || cfg->divergence < 0 ||
        (cfg->pairs != TCB_PAIRS_NEIGHBORS && cfg->pairs != TCB_PAIRS_RANDOM))
        return tcb_fail(err, TCB_ERR_INPUT,
                        "atlas: uv_samples %d must be a positive multiple of patches %d, delta %d ≥ 1, "
                        "iterations %lld ≥ 1, divergence %g ≥ 0", cfg->M, model->P, cfg->delta, cfg->iterations,
                        cfg->divergence);
    tcb_atlas_trainer *t = calloc(1, sizeof *t);
    if (!t) return tcb_fail(err, TCB_ERR_NOMEM, "atlas: out of memory");
    t->cfg = *cfg, t->model = model, t->N = seq->input_points;
    tcb_rng_seed_stream(&t->rng, seed, "atlas/train");
    size_t bm3 = (size_t)TCB_ATLAS_BATCH * cfg->M * 3;
    t->clouds = malloc((size_t)TCB_ATLAS_BATCH * t->N * 3 * sizeof(float));
    t->uv = malloc((size_t)cfg->M * 2 * sizeof(float));
    float **bufs[] = {&t->phi, &t->phi_u, &t->phi_v, &t->dphi, &t->dphi_u, &t->dphi_v};
    int ok = t->clouds && t->uv;
    for (size_t k = 0; k < sizeof bufs / sizeof bufs[0]; k++) ok &= (*bufs[k] = malloc(bm3 * sizeof(float))) != NULL;
    int rc = ok ? TCB_OK : tcb_fail(err, TCB_ERR_NOMEM, "atlas: out of memory for training buffers");
    if (!rc) rc = tcb_adam_init(&t->adam, model->nparams, err);
    if (!rc) rc = tcb_atlas_work_create(model, TCB_ATLAS_BATCH, t->N, cfg->M, &t->work, err);
    if (rc) {
        tcb_atlas_trainer_free(t);
        return rc;
    }
    *out = t;
    return TCB_OK;
}

void tcb_atlas_trainer_free(tcb_atlas_trainer *t)
{
    if (!t) return;
    tcb_atlas_work_free(t->work);
    tcb_adam_free(&t->adam);
    free(t->clouds), free(t->uv);
    free(t->phi), free(t->phi_u), free(t->phi_v);
    free(t->dphi), free(t->dphi_u), free(t->dphi_v);
    free(t);
}

/* Two training pairs, their clouds and the shared UV samples. */
static int draw_batch(tcb_atlas_trainer *t, const tcb_sequence *seq, tcb_error *err)
{
    for (int p = 0; p < TCB_ATLAS_BATCH / 2; p++) {
        int lo, hi, a = (int)tcb_rng_below(&t->rng, (uint32_t)seq->n_frames);
        /* neighbors: a's block (subject) only; random: the whole sequence (§1.4) */
        tcb_seq_block_of(seq, a, &lo, &hi);
        int b = tcb_pair_sample(t->cfg.pairs, t->cfg.delta, seq->n_frames, lo, hi, a, &t->rng);
        if (b < 0) return tcb_fail(err, TCB_ERR_INTERNAL, "atlas: no partner frame for frame %d", a);
        t->frames[2 * p] = a, t->frames[2 * p + 1] = b;
    }
    for (int k = 0; k < TCB_ATLAS_BATCH; k++) {
        int f = t->frames[k];
        t->area[k] = seq->areas[f];
        int rc = tcb_sequence_draw_points(seq, f, t->N, seq->draw_with_replacement, &t->rng,
                                          t->clouds + (size_t)k * t->N * 3, err);
        if (rc) return rc;
    }
    for (int k = 0; k < 2 * t->cfg.M; k++) t->uv[k] = (float)tcb_rng_uniform(&t->rng);
    return TCB_OK;
}

/* Total loss, with its gradient w.r.t. φ (and the tangents) in dphi*. */
static int loss_and_grad(tcb_atlas_trainer *t, double *loss, tcb_error *err)
{
    const tcb_atlas_train_cfg *c = &t->cfg;
    int B = TCB_ATLAS_BATCH, M = c->M;
    size_t bm3 = (size_t)B * M * 3 * sizeof(float);
    memset(t->dphi, 0, bm3);
    memset(t->dphi_u, 0, bm3);
    memset(t->dphi_v, 0, bm3);
    double cd = 0, reg = 0;
    int rc = tcb_atlas_chamfer_loss(t->phi, t->clouds, B, M, t->N, 1.0f, &cd, t->dphi, err);
    if (!rc && c->loss == TCB_ATLAS_LOSS_METRIC) {
        rc = tcb_atlas_metric_loss(t->phi_u, t->phi_v, B, M, (float)c->alpha_mc, &reg, t->dphi_u,
                                   t->dphi_v, err);
        reg *= c->alpha_mc;
    }
    if (!rc && c->loss == TCB_ATLAS_LOSS_DSR) {
        tcb_atlas_dsr_weights w = tcb_atlas_dsr_defaults();
        rc = tcb_atlas_dsr_loss(t->phi_u, t->phi_v, B, M, t->model->P, t->area, &w,
                                (float)c->alpha_sciso, &reg, NULL, t->dphi_u, t->dphi_v, err);
        reg *= c->alpha_sciso;
    }
    *loss = cd + reg;
    if (!rc && !isfinite(*loss)) rc = tcb_fail(err, TCB_ERR_NUMERIC, "atlas: loss is %g", *loss);
    return rc;
}

int tcb_atlas_train_step(tcb_atlas_trainer *t, const tcb_sequence *seq, double *loss, tcb_error *err)
{
    int tan = uses_tangents(&t->cfg);
    int rc = draw_batch(t, seq, err);
    if (rc) return rc;
    tcb_atlas_model_forward(t->model, t->work, t->clouds, t->uv, t->phi, tan ? t->phi_u : NULL,
                            tan ? t->phi_v : NULL);
    rc = loss_and_grad(t, loss, err);
    if (!rc) {
        tcb_atlas_model_zero_grad(t->model);
        rc = tcb_atlas_model_backward(t->model, t->work, t->dphi, tan ? t->dphi_u : NULL,
                                      tan ? t->dphi_v : NULL, err);
    }
    if (!rc)
        rc = tcb_train_guard("atlas", t->it, *loss, t->model->grads, t->model->nparams, t->cfg.divergence,
                             &t->loss0, err);
    else
        tcb_error_prefix(err, "iteration %lld: ", t->it);
    if (rc) return rc;
    tcb_adam_step(&t->adam, t->model->params, t->model->grads,
                        tcb_lr_at(t->cfg.lr, t->it, t->cfg.iterations));
    t->it++;
    return TCB_OK;
}
