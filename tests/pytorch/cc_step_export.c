/* Test helper for tests/pytorch/cc_step_check.py: ONE training step
 * (tcb_cc_train_step) of a small CC network on a short synthetic sequence,
 * in two cases, each written into DIR/<case>/:
 *   warmup   cfg.warmup = cfg.iterations: the step runs the eight network
 *            calls (six pairs, then the self-reconstruction pair (C, C')
 *            and (C', C)) and adds the self-reconstruction term;
 *   steady   cfg.warmup = 0: the six pair calls only.
 * Files:
 *     weights.bin, weights.json   the network before the step (tcb_cc_net_export:
 *                                 parameters, then the running statistics)
 *     updated.bin, updated.json   the network after the step's Adam update,
 *                                 with the running statistics the step moved
 *     grads.f32 [nparams]         the step's gradient (net->grads; Adam does not touch it)
 *     clouds.f32 [n][B][N][3]     the network inputs, after augmentation
 *                                 (t->clouds): A, B, C and, in the warm-up, C'
 *                                 (n = 4, else 3)
 *     rot.f32 [B][9]              C's augmentation rotation (t->rot), from
 *                                 which C' was made
 *     matches.i32 [6][B][N]       the trainer's nearest-neighbour maps n_k
 *                                 (tcb_cc_losses_matches; int32): for each
 *                                 deformed point of pair k, its nearest target
 *     backward.i32 [6][B][N]      for each target point, its nearest deformed
 *                                 point: tcb_nn_nearest on the same arrays as
 *                                 losses.c's match_block (which keeps this map
 *                                 private), so the same answer
 *     D.f32, gD.f32 [calls][B][N][3]
 *                                 the network outputs of the step's calls
 *                                 (t->D: 8 or 6) and the loss gradient
 *                                 w.r.t. them (t->gD)
 *     case.json                   sizes, the frames, the loss and its terms
 *                                 (t->last), the step's lr and Adam's β1, β2, eps
 * (raw little-endian, see export.h).
 *
 * The case is built to keep the step as well conditioned as a float32
 * check allows (measure: torch in float64 with its parameters multiplied
 * by 1 ± 6e-8 at random; its gradient moves by ≤ 2.2e-5 of each tensor's
 * largest entry here, while torch's own float32 step is still 1.7e-4 off
 * its float64 one, see cc_step_check.py):
 *   * B = 8 triplets and L = 2 (fc_0, fc_1, fc_end: every kind of meta
 *     layer), not 3 and 3: with 3 rows the batch norms over the shapes
 *     (the encoders' last one, the predictor's) turn the one-step gradient
 *     ill-conditioned — the same perturbation moves it by up to 7e-3
 *     (B 3, N 150, L 3), beyond any 1e-4 check; B 6 still 3e-4, and
 *     each predicted W + I adds to it (B 8, L 3: 8e-5);
 *   * each frame stretched by its own per-axis factors (stretch[]; the CC
 *     box normalizes the scale, not the proportions), so the triplets'
 *     shapes differ more than a walk's frames do;
 *   * every 1×1 convolution's weights scaled by CONV_GAIN / √fan_in, from
 *     CC's N(0, 0.02) to N(0, 1/fan_in): with CC's 0.02 the last layer's
 *     tanh sees ~0.05 around its bias and each deformed shape shrinks to
 *     an extent of ~0.14 (2.3 here), its nearest-neighbour gaps 10× smaller;
 *     the backward alone is then 1.2e-4 off float64 and torch's own
 *     float32 gradient 7e-3 (build with -DCC_STEP_NO_GAIN to see).
 * Still, the C forward's float32 outputs differ from float64 by up to
 * ~6e-5 of their range, enough to flip a near tie among the 9600
 * nearest-neighbour queries of a step, and tcb_nn's float32 squared
 * distances can order two candidates whose distances differ by less
 * than float32 resolution either way; so the check takes the indices
 * from the C side (matches.i32, backward.i32) after verifying that each
 * is a nearest neighbour up to such ties. A structural property of CC's
 * network also shows here: the first meta layer applies ReLU(bn0(·)) to
 * 3 channels, so the points whose three are all dead map to one common
 * point (8.5 % of a deformed shape on average here, up to 45 %; 1/8 if
 * the three were independent and symmetric): exact ties in float64,
 * ties to the last bits in float32.
 *
 * usage: cc_step_export DIR */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

#include "methods/cycle/train.h"
#include "tcb/nn.h"
#include "tcb/synth.h"
#include "tests/pytorch/export.h"

enum { C = 32, Z = 16, H = 8, L = 2, B = 8, N = 100, POOL = 600, FRAMES = 6, ITERATIONS = 100 };
#define CONV_GAIN 50.0

static int make_sequence(tcb_sequence *s, tcb_error *err)
{
    int rc = tcb_synth_generate("quadruped_walk", 1, FRAMES, s, err);
    if (!rc) rc = tcb_sequence_normalize(s, TCB_NORM_FIRST_FRAME, err);
    if (!rc) rc = tcb_sequence_sample_pools(s, POOL, 1, err);
    if (rc) return rc;
    s->input_points = N, s->draw_with_replacement = 0;
    static const float stretch[FRAMES][3] = {{1, 0.5f, 0.8f},    {0.4f, 1, 1},      {1, 1, 0.3f},
                                             {0.6f, 0.35f, 1}, {1, 0.7f, 0.45f}, {0.5f, 1, 0.6f}};
    for (int f = 0; f < FRAMES; f++) {
        float *q = s->pools + (size_t)f * s->pool_size * 3;
        for (int i = 0; i < s->pool_size; i++)
            for (int c = 0; c < 3; c++) q[3 * i + c] *= stretch[f][c];
    }
    return TCB_OK;
}

static void gain(const tcb_linear *conv)
{
#ifdef CC_STEP_NO_GAIN /* CC's own initialisation, for the measurements above */
    (void)conv;
    return;
#endif
    double k = CONV_GAIN / sqrt((double)conv->in);
    for (size_t i = 0; i < (size_t)conv->in * conv->out; i++) conv->W[i] = (float)(conv->W[i] * k);
}

static void init_net(tcb_cc_net *n)
{
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 2024, "tests/pytorch/cc_step");
    tcb_cc_net_init(n, &rng);
    for (int e = 0; e < 2; e++) gain(&n->p.enc[e].conv1), gain(&n->p.enc[e].conv2), gain(&n->p.enc[e].conv3);
    for (int l = 0; l < n->n_meta; l++) gain(&n->p.meta[l].conv);
}

static int export_i32(const char *dir, const char *name, const int32_t *x, size_t n)
{
    char path[EXPORT_PATH_MAX];
    if (export_path(path, dir, name)) return 1;
    FILE *fp = fopen(path, "wb");
    int ok = fp && fwrite(x, sizeof *x, n, fp) == n;
    if (fp && fclose(fp)) ok = 0;
    if (!ok) fprintf(stderr, "cc_step_export: cannot write %s\n", path);
    return ok ? 0 : 1;
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

static int write_case(const char *dir, const char *name, const tcb_cc_trainer *t, int warmup, double loss,
                      double lr)
{
    char path[EXPORT_PATH_MAX];
    if (export_path(path, dir, "case.json")) return 1;
    FILE *fp = fopen(path, "w");
    if (!fp) {
        fprintf(stderr, "cc_step_export: cannot write %s\n", path);
        return 1;
    }
    const tcb_cc_train_terms *l = &t->last;
    fprintf(fp, "{\"case\": \"%s\", \"warmup\": %d,", name, warmup);
    fprintf(fp, " \"C\": %d, \"Z\": %d, \"H\": %d, \"L\": %d, \"B\": %d, \"N\": %d,\n", C, Z, H, L, B, N);
    fprintf(fp, " \"n_clouds\": %d, \"conv_gain\": %g, \"frames\": [", warmup ? 4 : 3, CONV_GAIN);
    for (int c = 0; c < 3; c++)
        for (int b = 0; b < B; b++) fprintf(fp, "%s%d", c || b ? ", " : "", t->frames[c][b]);
    fprintf(fp, "],\n \"loss\": %.17g, \"chamfer\": %.17g, \"cycle2\": %.17g, \"cycle3\": %.17g,\n", loss,
            l->cycle.chamfer, l->cycle.cycle2, l->cycle.cycle3);
    fprintf(fp, " \"selfrec\": %.17g, \"total\": %.17g, \"lr\": %.17g,\n", l->selfrec, l->total, lr);
    fprintf(fp, " \"beta1\": %.17g, \"beta2\": %.17g, \"eps\": %.17g}\n", t->adam.b1, t->adam.b2,
            t->adam.eps);
    return fclose(fp) ? 1 : 0;
}

/* The nearest-neighbour maps of the step's six pairs: matches.i32 from
 * the trainer, backward.i32 recomputed as losses.c's match_block does. */
static int export_matches(const char *dir, const tcb_cc_trainer *t)
{
    static int32_t fwd[TCB_CC_PAIRS][B][N], bwd[TCB_CC_PAIRS][B][N];
    size_t bn3 = (size_t)B * N * 3;
    tcb_error err = {0};
    for (int k = 0; k < TCB_CC_PAIRS; k++) {
        const int32_t *m = tcb_cc_losses_matches(t->losses, k);
        if (!m) return 1;
        memcpy(fwd[k], m, sizeof fwd[k]);
        for (int b = 0; b < B; b++) {
            const float *d = t->D + k * bn3 + (size_t)b * N * 3;
            const float *target = t->clouds + tcb_cc_pairs[k][1] * bn3 + (size_t)b * N * 3;
            if (tcb_nn_nearest(d, N, target, N, bwd[k][b], NULL, &err)) {
                fprintf(stderr, "cc_step_export: %s\n", err.msg);
                return 1;
            }
        }
    }
    return export_i32(dir, "matches.i32", &fwd[0][0][0], sizeof fwd / sizeof(int32_t)) |
           export_i32(dir, "backward.i32", &bwd[0][0][0], sizeof bwd / sizeof(int32_t));
}

/* One step of a fresh network and trainer, into DIR/<name>. */
static int export_step(const char *root, const char *name, int warmup, const tcb_sequence *seq,
                       tcb_error *err)
{
    char dir[EXPORT_PATH_MAX];
    if (export_path(dir, root, name) || mkdir(dir, 0777))
        return tcb_fail(err, TCB_ERR_IO, "cannot create %s", dir);
    tcb_cc_dims d = {.C = C, .Z = Z, .H = H, .L = L};
    tcb_cc_net *net = NULL;
    int rc = tcb_cc_net_create(&d, &net, err);
    if (rc) return rc;
    init_net(net);
    tcb_cc_train_cfg cfg = {.sampler = tcb_cc_sampler_opts_default(), .batch = B, .iterations = ITERATIONS,
                            .warmup = warmup ? ITERATIONS : 0, .lr = 1e-3, .divergence = 0};
    tcb_cc_trainer *t = NULL;
    double loss = 0;
    rc = export_net(net, dir, "weights", err);
    if (!rc) rc = tcb_cc_trainer_create(&cfg, net, seq, 7, &t, err);
    if (!rc) rc = tcb_cc_train_step(t, seq, &loss, err);
    if (!rc) rc = export_net(net, dir, "updated", err);
    double lr = tcb_lr_at(cfg.lr, 0, cfg.iterations); /* the lr of iteration 0 */
    size_t bn3 = (size_t)B * N * 3;
    if (!rc && (write_case(dir, name, t, warmup, loss, lr) |
                export_f32(dir, "grads.f32", net->grads, net->nparams) |
                export_f32(dir, "clouds.f32", t->clouds, (warmup ? 4 : 3) * bn3) |
                export_f32(dir, "rot.f32", &t->rot[0][0], (size_t)B * 9) | export_matches(dir, t) |
                export_f32(dir, "D.f32", t->D, (warmup ? TCB_CC_CALLS : TCB_CC_PAIRS) * bn3) |
                export_f32(dir, "gD.f32", t->gD, (warmup ? TCB_CC_CALLS : TCB_CC_PAIRS) * bn3)))
        rc = tcb_fail(err, TCB_ERR_IO, "cannot write the step %s", name);
    tcb_cc_trainer_free(t);
    tcb_cc_net_free(net);
    return rc;
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: cc_step_export DIR\n");
        return 2;
    }
    tcb_error err = {0};
    tcb_sequence seq = {0};
    int rc = make_sequence(&seq, &err);
    if (!rc) rc = export_step(argv[1], "warmup", 1, &seq, &err);
    if (!rc) rc = export_step(argv[1], "steady", 0, &seq, &err);
    if (rc) fprintf(stderr, "cc_step_export: %s\n", err.msg);
    tcb_sequence_free(&seq);
    return rc ? 1 : 0;
}
