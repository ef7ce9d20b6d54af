#include "methods/cycle/train.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "neural/train_loop.h"

/* Network call k deforms cloud x towards cloud y: encoder 0 encodes x,
 * encoder 1 encodes y. Calls 0..5 are the pairs of tcb_cc_pairs (the CC
 * code's triplet_chamfer_loss order), 6 and 7 the self-reconstruction
 * network(P3, P4) and network(P4, P3). */
static void call_clouds(int k, int *x, int *y)
{
    if (k < TCB_CC_PAIRS) *x = tcb_cc_pairs[k][0], *y = tcb_cc_pairs[k][1];
    else *x = k == 6 ? 2 : 3, *y = k == 6 ? 3 : 2;
}

static size_t cloud_floats(const tcb_cc_trainer *t) { return (size_t)t->cfg.batch * t->N * 3; }

static int check_cfg(const tcb_cc_train_cfg *c, const tcb_sequence *seq, tcb_error *err)
{
    if (seq->n_frames < 2 || seq->pool_size < 1 || seq->input_points < 2)
        return tcb_fail(err, TCB_ERR_INPUT,
                        "cc: sequence %s needs at least 2 frames, point pools and input_points > 1 "
                        "(has %d frames, pool %d, input_points %d)",
                        seq->name, seq->n_frames, seq->pool_size, seq->input_points);
    if (c->batch < 2 || c->batch > TCB_CC_MAX_BATCH || c->iterations < 1 || c->warmup < 0 ||
        c->warmup > c->iterations || c->divergence < 0 || !(c->lr > 0))
        return tcb_fail(err, TCB_ERR_INPUT,
                        "cc: batch %d must be 2..%d (batch norm needs two shapes), iterations %lld ≥ 1, "
                        "warmup %lld within 0..iterations, divergence %g ≥ 0, lr %g > 0",
                        c->batch, TCB_CC_MAX_BATCH, c->iterations, c->warmup, c->divergence, c->lr);
    return TCB_OK;
}

static int alloc_buffers(tcb_cc_trainer *t, tcb_error *err)
{
    const tcb_cc_dims *d = &t->net->d;
    int B = t->cfg.batch, N = t->N;
    size_t bn3 = cloud_floats(t), sc = tcb_cc_encoder_scratch_floats(d, B, N),
           sd = tcb_cc_deform_scratch_floats(t->net, B, N);
    t->clouds = malloc(TCB_CC_CLOUDS * bn3 * sizeof(float));
    t->D = malloc(TCB_CC_CALLS * bn3 * sizeof(float));
    t->gD = malloc(TCB_CC_CALLS * bn3 * sizeof(float));
    t->scratch = malloc((sc > sd ? sc : sd) * sizeof(float));
    t->boxes = malloc((size_t)t->n_frames * sizeof *t->boxes);
    int rc = t->clouds && t->D && t->gD && t->scratch && t->boxes
                 ? TCB_OK
                 : tcb_fail(err, TCB_ERR_NOMEM, "cc: out of memory for training buffers");
    for (int e = 0; !rc && e < 2; e++)
        for (int c = 0; !rc && c < TCB_CC_CLOUDS; c++) {
            rc = tcb_cc_encoder_cache_alloc(&t->enc[e][c], d, B, N, err);
            if (!rc && !(t->dz[e][c] = malloc((size_t)B * d->Z * sizeof(float))))
                rc = tcb_fail(err, TCB_ERR_NOMEM, "cc: out of memory for training buffers");
        }
    for (int k = 0; !rc && k < TCB_CC_CALLS; k++) rc = tcb_cc_deform_cache_alloc(&t->dec[k], t->net, B, N, err);
    return rc;
}

int tcb_cc_trainer_create(const tcb_cc_train_cfg *cfg, tcb_cc_net *net, const tcb_sequence *seq,
                          uint64_t seed, tcb_cc_trainer **out, tcb_error *err)
{
    *out = NULL;
    int rc = check_cfg(cfg, seq, err);
    if (rc) return rc;
    tcb_cc_trainer *t = calloc(1, sizeof *t);
    if (!t) return tcb_fail(err, TCB_ERR_NOMEM, "cc: out of memory");
    t->cfg = *cfg, t->net = net, t->N = seq->input_points, t->n_frames = seq->n_frames;
    tcb_rng_seed_stream(&t->rng, seed, "cc/train");
    rc = alloc_buffers(t, err);
    for (int f = 0; !rc && f < seq->n_frames; f++) rc = tcb_cc_frame_box_compute(seq, f, &t->boxes[f], err);
    if (!rc) rc = tcb_cc_sampler_create(seq, &cfg->sampler, &t->sampler, err);
    if (!rc) rc = tcb_cc_losses_create(cfg->batch, t->N, &t->losses, err);
    if (!rc) rc = tcb_adam_init(&t->adam, net->nparams, err);
    if (rc) {
        tcb_cc_trainer_free(t);
        return rc;
    }
    *out = t;
    return TCB_OK;
}

void tcb_cc_trainer_free(tcb_cc_trainer *t)
{
    if (!t) return;
    for (int e = 0; e < 2; e++)
        for (int c = 0; c < TCB_CC_CLOUDS; c++) tcb_cc_encoder_cache_free(&t->enc[e][c]), free(t->dz[e][c]);
    for (int k = 0; k < TCB_CC_CALLS; k++) tcb_cc_deform_cache_free(&t->dec[k]);
    tcb_cc_sampler_free(t->sampler);
    tcb_cc_losses_free(t->losses);
    tcb_adam_free(&t->adam);
    free(t->clouds), free(t->D), free(t->gD), free(t->scratch), free(t->boxes);
    free(t);
}

static int in_warmup(const tcb_cc_trainer *t) { return t->it < t->cfg.warmup; }

/* The triplets and their augmented clouds, triplet by triplet (A, B, C as
 * the CC code's getAnItem: draw, box, augment), then during the warm-up
 * each shape's self-reconstruction target C'. */
static int draw_batch(tcb_cc_trainer *t, const tcb_sequence *seq, tcb_error *err)
{
    int B = t->cfg.batch, N = t->N;
    size_t bn3 = cloud_floats(t);
    for (int b = 0; b < B; b++) {
        int f[3];
        tcb_cc_sampler_draw(t->sampler, &t->rng, f);
        for (int c = 0; c < 3; c++) {
            float *pts = t->clouds + c * bn3 + (size_t)b * N * 3;
            tcb_cc_aug aug;
            t->frames[c][b] = f[c];
            int rc = tcb_sequence_draw_points(seq, f[c], N, seq->draw_with_replacement, &t->rng, pts, err);
            if (!rc) tcb_cc_frame_box_apply(&t->boxes[f[c]], pts, N, pts);
            if (!rc) rc = tcb_cc_augment(pts, N, &t->rng, &aug, err);
            if (rc) return rc;
            if (c == 2) memcpy(t->rot[b], aug.rot, sizeof aug.rot);
        }
    }
    for (int b = 0; in_warmup(t) && b < B; b++) {
        float s[3];
        tcb_cc_selfrec_draw_scale(&t->rng, s);
        tcb_cc_selfrec_target(t->clouds + 2 * bn3 + (size_t)b * N * 3, N, t->rot[b], s,
                              t->clouds + 3 * bn3 + (size_t)b * N * 3);
    }
    return TCB_OK;
}

/* Encoder e's code of cloud c. Pair calls reuse a code computed earlier in
 * the iteration (the CC code's cached latents); `rerun` calls are fresh
 * PyTorch forwards, which move the running statistics again. */
static const float *encode(tcb_cc_trainer *t, int e, int c, int rerun)
{
    tcb_cc_encoder_cache *ec = &t->enc[e][c];
    const tcb_cc_encoder *enc = &t->net->p.enc[e];
    if (!t->encoded[e][c]) {
        tcb_cc_encoder_forward(enc, ec, t->scratch, t->clouds + c * cloud_floats(t), 1);
        t->encoded[e][c] = 1;
    } else if (rerun) {
        tcb_cc_encoder_count_again(enc, ec);
    }
    return ec->z;
}

static void forward(tcb_cc_trainer *t, int n_calls)
{
    size_t bn3 = cloud_floats(t);
    memset(t->encoded, 0, sizeof t->encoded);
    for (int k = 0; k < n_calls; k++) {
        int x, y, rerun = k >= TCB_CC_PAIRS;
        call_clouds(k, &x, &y);
        const float *zx = encode(t, 0, x, rerun), *zy = encode(t, 1, y, rerun);
        tcb_cc_deform_forward(t->net, &t->dec[k], t->scratch, zx, zy, t->clouds + x * bn3, 1);
        memcpy(t->D + k * bn3, t->dec[k].out, bn3 * sizeof(float));
    }
}

/* The losses, with ∂/∂D of each call in t->gD. */
static int losses(tcb_cc_trainer *t, int n_calls, tcb_error *err)
{
    static const tcb_cc_loss_weights unit = {1, 1, 1};
    size_t bn3 = cloud_floats(t);
    tcb_cc_train_terms *l = &t->last;
    int rc = tcb_cc_losses_eval(t->losses, t->clouds, t->D, t->cfg.batch, &unit, &l->cycle, t->gD, err);
    if (rc) return rc;
    l->selfrec = 0;
    if (n_calls > TCB_CC_PAIRS) {
        /* ½(L2(P4_P3, P4) + L2(P3_P4, P3)): call 6 deforms C towards C', 7 C' towards C */
        float *g6 = t->gD + 6 * bn3, *g7 = t->gD + 7 * bn3;
        l->selfrec = 0.5 * (tcb_cc_rms(t->D + 6 * bn3, t->clouds + 3 * bn3, bn3, g6) +
                            tcb_cc_rms(t->D + 7 * bn3, t->clouds + 2 * bn3, bn3, g7));
        for (size_t k = 0; k < bn3; k++) g6[k] *= 0.5f, g7[k] *= 0.5f;
    }
    l->total = l->cycle.total + l->selfrec;
    if (!isfinite(l->total)) return tcb_fail(err, TCB_ERR_NUMERIC, "cc: loss is %g", l->total);
    return TCB_OK;
}

static void backward(tcb_cc_trainer *t, int n_calls)
{
    size_t bn3 = cloud_floats(t), nz = (size_t)t->cfg.batch * t->net->d.Z;
    tcb_cc_net_zero_grad(t->net);
    for (int e = 0; e < 2; e++)
        for (int c = 0; c < TCB_CC_CLOUDS; c++) memset(t->dz[e][c], 0, nz * sizeof(float));
    for (int k = n_calls - 1; k >= 0; k--) {
        int x, y;
        call_clouds(k, &x, &y);
        tcb_cc_deform_backward(t->net, &t->dec[k], t->scratch, t->gD + k * bn3, t->dz[0][x], t->dz[1][y]);
    }
    for (int e = 0; e < 2; e++)
        for (int c = 0; c < TCB_CC_CLOUDS; c++)
            if (t->encoded[e][c])
                tcb_cc_encoder_backward(&t->net->p.enc[e], &t->net->g.enc[e], &t->enc[e][c], t->scratch,
                                        t->dz[e][c]);
}

int tcb_cc_train_step(tcb_cc_trainer *t, const tcb_sequence *seq, double *loss, tcb_error *err)
{
    int n_calls = in_warmup(t) ? TCB_CC_CALLS : TCB_CC_PAIRS;
    int rc = draw_batch(t, seq, err);
    if (!rc) {
        forward(t, n_calls);
        rc = losses(t, n_calls, err);
    }
    if (!rc) {
        *loss = t->last.total;
        backward(t, n_calls);
        rc = tcb_train_guard("cc", t->it, *loss, t->net->grads, t->net->nparams, t->cfg.divergence,
                             &t->loss0, err);
    } else {
        tcb_error_prefix(err, "iteration %lld: ", t->it);
    }
    if (rc) return rc;
    double lr = tcb_lr_at(t->cfg.lr, t->it, t->cfg.iterations);
    /* the CC code recreates Adam at each decay (learning_rate_scheduler) */
    if (t->it > 0 && lr != tcb_lr_at(t->cfg.lr, t->it - 1, t->cfg.iterations)) tcb_adam_reset(&t->adam);
    tcb_adam_step(&t->adam, t->net->params, t->net->grads, lr);
    t->it++;
    return TCB_OK;
}
