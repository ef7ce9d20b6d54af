/* Test helper for tests/pytorch/cc_net_check.py: one training-mode forward
 * and backward of a small CC network (methods/cycle: two encoders and the
 * deformation decoder) on fixed random clouds, then an evaluation-mode
 * forward, with everything PyTorch needs to redo them, written into DIR:
 *     weights.bin, weights.json   the network before (tcb_cc_net_export)
 *     after.bin, after.json       the same after the training forward: the
 *                                 running statistics moved once per batch norm
 *     case.json                   sizes
 *     x.f32, y.f32 [B][N][3]      source and target clouds
 *     coef.f32 [B][N][3]          the objective's weights a
 *     out_train.f32 [B][N][3]     the training-mode output (x deformed towards y)
 *     grads.f32 [nparams]         ∂(Σ a·out_train)/∂params
 *     out_eval.f32 [B][N][3]      the evaluation-mode output, with the
 *                                 running statistics of after.bin
 * (raw float32, see export.h).
 *
 * The weights are tcb_cc_net_init's, changed so that every part of the
 * computation carries a visible share of the result: every batch norm's γ,
 * β and running statistics are drawn at random (γ ∈ U(0.5, 1.5), β, r_μ ∈
 * U(−0.5, 0.5), r_σ² ∈ U(0.5, 2): at init β = 0 and the statistics are
 * 0 and 1, which would hide a swapped or ignored tensor), and every 1×1
 * convolution's weights are scaled by CONV_GAIN / √fan_in, from CC's
 * N(0, 0.02) to N(0, 1/fan_in) at CONV_GAIN 50. With CC's 0.02 the
 * convolution outputs are their bias plus variations of ~1 % (batch norm
 * in training mode takes the bias out, but in evaluation mode each channel
 * would be nearly a constant), and the last layer's tanh would act on
 * ~0.05 around its bias (almost linear): the deformed points would
 * collapse to one point per shape.
 *
 * usage: cc_export DIR */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "methods/cycle/deform.h"
#include "methods/cycle/encoder.h"
#include "methods/cycle/net.h"
#include "tests/pytorch/export.h"

enum { C = 32, Z = 16, H = 8, L = 3, B = 3, N = 200 };
#define CONV_GAIN 50.0

static void fill(tcb_rng *r, float *x, size_t n, double lo, double hi)
{
    for (size_t i = 0; i < n; i++) x[i] = (float)(lo + (hi - lo) * tcb_rng_uniform(r));
}

/* B clouds [B][N][3] of N points, each uniform in its own box: per shape
 * and axis a half-extent U(0.2, 1) and a centre U(−0.5, 0.5). Clouds drawn
 * from one distribution would have nearly equal max-pooled features, and
 * the batch norms over the B shapes (bnf, the predictor's) would amplify
 * float32 rounding by their cancellation (torch float32 against float64:
 * 1e-4 of the output). */
static void fill_clouds(tcb_rng *r, float *x)
{
    for (int b = 0; b < B; b++) {
        double half[3], mid[3];
        for (int c = 0; c < 3; c++)
            half[c] = 0.2 + 0.8 * tcb_rng_uniform(r), mid[c] = tcb_rng_uniform(r) - 0.5;
        for (int i = 0; i < N; i++)
            for (int c = 0; c < 3; c++)
                x[((size_t)b * N + i) * 3 + c] = (float)(mid[c] + half[c] * (2.0 * tcb_rng_uniform(r) - 1.0));
    }
}

static void perturb_bn(const tcb_batchnorm *bn, tcb_rng *r)
{
    fill(r, bn->gamma, bn->C, 0.5, 1.5);
    fill(r, bn->beta, bn->C, -0.5, 0.5);
    fill(r, bn->mean, bn->C, -0.5, 0.5);
    fill(r, bn->var, bn->C, 0.5, 2.0);
}

static void gain(const tcb_linear *conv)
{
    double k = CONV_GAIN / sqrt((double)conv->in);
    for (size_t i = 0; i < (size_t)conv->in * conv->out; i++) conv->W[i] = (float)(conv->W[i] * k);
}

/* tcb_cc_net_init, then the changes described at the top. */
static void init_net(tcb_cc_net *n, tcb_rng *r)
{
    tcb_cc_net_init(n, r);
    tcb_cc_views *v = &n->p;
    for (int e = 0; e < 2; e++) {
        tcb_cc_encoder *enc = &v->enc[e];
        perturb_bn(&enc->bn1, r), perturb_bn(&enc->bn2, r);
        perturb_bn(&enc->bn3, r), perturb_bn(&enc->bnf, r);
        gain(&enc->conv1), gain(&enc->conv2), gain(&enc->conv3);
    }
    perturb_bn(&v->pred.bn1, r), perturb_bn(&v->pred.bn2, r);
    for (int l = 0; l < n->n_meta; l++) {
        perturb_bn(&v->meta[l].bn0, r);
        if (v->meta[l].bn1.C) perturb_bn(&v->meta[l].bn1, r);
        gain(&v->meta[l].conv);
    }
}

static int export_net(const tcb_cc_net *n, const char *dir, const char *stem, tcb_error *err)
{
    char bin[EXPORT_PATH_MAX], json[EXPORT_PATH_MAX], name[256];
    snprintf(name, sizeof name, "%s.bin", stem);
    int rc = export_path(bin, dir, name);
    snprintf(name, sizeof name, "%s.json", stem);
    if (rc | export_path(json, dir, name)) return tcb_fail(err, TCB_ERR_IO, "path too long under %s", dir);
    return tcb_cc_net_export(n, bin, json, err);
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: cc_export DIR\n");
        return 2;
    }
    const char *dir = argv[1];
    tcb_error err = {0};
    tcb_cc_dims d = {.C = C, .Z = Z, .H = H, .L = L};
    tcb_cc_net *net = NULL;
    tcb_cc_encoder_cache ex = {0}, ey = {0};
    tcb_cc_deform_cache dc = {0};
    int rc = tcb_cc_net_create(&d, &net, &err);
    if (!rc) rc = tcb_cc_encoder_cache_alloc(&ex, &d, B, N, &err);
    if (!rc) rc = tcb_cc_encoder_cache_alloc(&ey, &d, B, N, &err);
    if (!rc) rc = tcb_cc_deform_cache_alloc(&dc, net, B, N, &err);
    if (rc) {
        fprintf(stderr, "cc_export: %s\n", err.msg);
        return 1;
    }
    size_t se = tcb_cc_encoder_scratch_floats(&d, B, N), sd = tcb_cc_deform_scratch_floats(net, B, N);
    float *scratch = malloc((se > sd ? se : sd) * sizeof(float));
    float *dzx = calloc((size_t)B * Z, sizeof(float)), *dzy = calloc((size_t)B * Z, sizeof(float));
    static float x[B * N * 3], y[B * N * 3], coef[B * N * 3], out_train[B * N * 3], out_eval[B * N * 3];
    if (!scratch || !dzx || !dzy) {
        fprintf(stderr, "cc_export: out of memory\n");
        return 1;
    }

    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 2024, "tests/pytorch/cc");
    init_net(net, &rng);
    fill_clouds(&rng, x);
    fill_clouds(&rng, y);
    fill(&rng, coef, B * N * 3, -1, 1);
    rc = export_net(net, dir, "weights", &err);

    /* training mode: x deformed towards y, then ∂(Σ a·out)/∂params as the
     * trainer's backward does it (decoder, then each encoder from its dz) */
    tcb_cc_encoder_forward(&net->p.enc[0], &ex, scratch, x, 1);
    tcb_cc_encoder_forward(&net->p.enc[1], &ey, scratch, y, 1);
    tcb_cc_deform_forward(net, &dc, scratch, ex.z, ey.z, x, 1);
    for (int i = 0; i < B * N * 3; i++) out_train[i] = dc.out[i];
    tcb_cc_net_zero_grad(net);
    tcb_cc_deform_backward(net, &dc, scratch, coef, dzx, dzy);
    tcb_cc_encoder_backward(&net->p.enc[0], &net->g.enc[0], &ex, scratch, dzx);
    tcb_cc_encoder_backward(&net->p.enc[1], &net->g.enc[1], &ey, scratch, dzy);
    if (!rc) rc = export_net(net, dir, "after", &err);

    /* evaluation mode with the moved running statistics */
    tcb_cc_encoder_forward(&net->p.enc[0], &ex, scratch, x, 0);
    tcb_cc_encoder_forward(&net->p.enc[1], &ey, scratch, y, 0);
    tcb_cc_deform_forward(net, &dc, scratch, ex.z, ey.z, x, 0);
    for (int i = 0; i < B * N * 3; i++) out_eval[i] = dc.out[i];
    if (rc) fprintf(stderr, "cc_export: %s\n", err.msg);

    char json[EXPORT_PATH_MAX];
    FILE *fp = rc || export_path(json, dir, "case.json") ? NULL : fopen(json, "w");
    if (!fp) rc = 1;
    else {
        fprintf(fp, "{\"C\": %d, \"Z\": %d, \"H\": %d, \"L\": %d, \"B\": %d, \"N\": %d,", C, Z, H, L, B, N);
        fprintf(fp, " \"conv_gain\": %g}\n", CONV_GAIN);
        if (fclose(fp)) rc = 1;
    }
    if (!rc)
        rc = export_f32(dir, "x.f32", x, B * N * 3) | export_f32(dir, "y.f32", y, B * N * 3) |
             export_f32(dir, "coef.f32", coef, B * N * 3) |
             export_f32(dir, "out_train.f32", out_train, B * N * 3) |
             export_f32(dir, "out_eval.f32", out_eval, B * N * 3) |
             export_f32(dir, "grads.f32", net->grads, net->nparams);
    free(scratch), free(dzx), free(dzy);
    tcb_cc_deform_cache_free(&dc);
    tcb_cc_encoder_cache_free(&ex), tcb_cc_encoder_cache_free(&ey);
    tcb_cc_net_free(net);
    return rc ? 1 : 0;
}
