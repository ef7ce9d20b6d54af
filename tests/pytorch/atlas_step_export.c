/* Test helper for tests/pytorch/atlas_step_check.py: ONE training step
 * (tcb_atlas_train_step) of each atlas method on a small network and a
 * short synthetic sequence, with everything PyTorch needs to redo it,
 * written into DIR/<method>/ for method = atlasnet, dsr, mca:
 *     weights.bin, weights.json   the model before the step (tcb_atlas_model_export)
 *     updated.bin, updated.json   the model after the step's Adam update
 *     grads.f32 [nparams]         the step's gradient, in the weights' layout
 *     clouds.f32 [4][N][3], uv.f32 [M][2]
 *                                 the step's batch: input clouds, UV samples
 *     case.json                   sizes, method, the batch's GT areas, the
 *                                 total loss, the step's lr and Adam's β1, β2, eps
 * (raw float32, see export.h).
 *
 * The case is built so that every term of each loss carries a visible share
 * of the gradient. At PyTorch's init a decoder is nearly constant in (u, v)
 * (E ≈ 1e-5) and the latent codes of two neighbouring frames differ by
 * 0.3 %, so L_mc's gradient would be ~1e-13 of Chamfer's and an error in it
 * would pass any 1e-4 check unseen (after 500 training steps 0.1·L_mc was
 * still 1e-8 beside L_CD = 0.016). Hence: every odd frame is its shape
 * scaled by ODD_SCALE (pools, vertices and GT area), so both shapes of each
 * neighbour pair differ; the decoders' first-layer weights are scaled by
 * FC1_GAIN (UV columns: large Jacobians; latent columns: metrics that depend
 * strongly on the shape) and their last layer by FC4_GAIN. Then L_mc's
 * metrics differ by ~40 % within a pair (no cancellation), 0.1·L_mc ≈ 2.3
 * beside L_CD ≈ 10 (its share of max |∂L/∂θ| is ≥ 2 % in every tensor,
 * median 38 %; the DSR terms' ≥ 28 %, median 63 %), and the predicted total
 * areas (7–9) lie between the even frames' GT area (1.1: the DSR area cap
 * is active) and the odd frames' (114: inactive).
 *
 * usage: atlas_step_export DIR */
#include <stdio.h>
#include <sys/stat.h>

#include "methods/atlas/train.h"
#include "tcb/synth.h"
#include "tests/pytorch/export.h"

enum { C = 32, P = 4, M = 200, N = 300, POOL = 600, FRAMES = 6 };
enum { ODD_SCALE = 10, FC1_GAIN = 100, FC4_GAIN = 3 };

static const struct {
    const char *name;
    tcb_atlas_loss loss;
} methods[] = {
    {"atlasnet", TCB_ATLAS_LOSS_CHAMFER},
    {"dsr", TCB_ATLAS_LOSS_DSR},
    {"mca", TCB_ATLAS_LOSS_METRIC},
};

static void scale_frame(tcb_sequence *s, int f, float k)
{
    float *v = s->verts + (size_t)f * s->n_verts * 3, *q = s->pools + (size_t)f * s->pool_size * 3;
    for (size_t i = 0; i < (size_t)s->n_verts * 3; i++) v[i] *= k;
    for (size_t i = 0; i < (size_t)s->pool_size * 3; i++) q[i] *= k;
    s->areas[f] *= (double)k * k;
}

static int make_sequence(tcb_sequence *s, tcb_error *err)
{
    int rc = tcb_synth_generate("quadruped_walk", 1, FRAMES, s, err);
    if (!rc) rc = tcb_sequence_normalize(s, TCB_NORM_FIRST_FRAME, err);
    if (!rc) rc = tcb_sequence_sample_pools(s, POOL, 1, err);
    if (rc) return rc;
    s->input_points = N, s->draw_with_replacement = 0;
    for (int f = 1; f < s->n_frames; f += 2) scale_frame(s, f, ODD_SCALE);
    return TCB_OK;
}

/* PyTorch's init, then the decoders' gains (see the top of the file). */
static void init_model(tcb_atlas_model *m)
{
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 2024, "tests/pytorch/atlas_step");
    tcb_atlas_model_init(m, &rng);
    for (int p = 0; p < m->P; p++) {
        tcb_linear *fc1 = &m->dec[p].l[0], *fc4 = &m->dec[p].l[TCB_ATLAS_DEC_LAYERS - 1];
        for (size_t i = 0; i < (size_t)fc1->in * fc1->out; i++) fc1->W[i] *= FC1_GAIN;
        for (size_t i = 0; i < (size_t)fc4->in * fc4->out; i++) fc4->W[i] *= FC4_GAIN;
    }
}

static int write_case(const char *dir, const char *method, const tcb_atlas_trainer *t,
                      double loss, double lr)
{
    char path[EXPORT_PATH_MAX];
    if (export_path(path, dir, "case.json")) return 1;
    FILE *fp = fopen(path, "w");
    if (!fp) {
        fprintf(stderr, "atlas_step_export: cannot write %s\n", path);
        return 1;
    }
    fprintf(fp, "{\"method\": \"%s\", \"C\": %d, \"P\": %d, \"B\": %d, \"N\": %d, \"M\": %d,\n",
            method, C, P, TCB_ATLAS_BATCH, N, M);
    fprintf(fp, " \"area\": [%.17g, %.17g, %.17g, %.17g],\n", t->area[0], t->area[1], t->area[2],
            t->area[3]);
    fprintf(fp, " \"loss\": %.17g, \"lr\": %.17g,\n", loss, lr);
    fprintf(fp, " \"beta1\": %.17g, \"beta2\": %.17g, \"eps\": %.17g}\n", t->adam.b1, t->adam.b2,
            t->adam.eps);
    return fclose(fp) ? 1 : 0;
}

/* One method's step, exported into DIR/<name>. */
static int export_step(const char *root, int k, const tcb_sequence *seq, tcb_error *err)
{
    char dir[EXPORT_PATH_MAX];
    if (export_path(dir, root, methods[k].name) || mkdir(dir, 0777))
        return tcb_fail(err, TCB_ERR_IO, "cannot create %s", dir);
    tcb_atlas_model *m;
    int rc = tcb_atlas_model_create(C, P, &m, err);
    if (rc) return rc;
    init_model(m);
    tcb_atlas_train_cfg cfg = {.loss = methods[k].loss, .M = M, .iterations = 1000, .lr = 1e-3,
                               .alpha_mc = 0.1, .alpha_sciso = 1e-3, .delta = 1};
    tcb_atlas_trainer *t = NULL;
    double loss = 0;
    rc = export_model(m, dir, "weights", err);
    if (!rc) rc = tcb_atlas_trainer_create(&cfg, m, seq, 7, &t, err);
    if (!rc) rc = tcb_atlas_train_step(t, seq, &loss, err);
    if (!rc) rc = export_model(m, dir, "updated", err);
    double lr = tcb_lr_at(cfg.lr, 0, cfg.iterations); /* the lr of iteration 0 */
    if (!rc && (write_case(dir, methods[k].name, t, loss, lr) |
                export_f32(dir, "grads.f32", m->grads, m->nparams) |
                export_f32(dir, "clouds.f32", t->clouds, (size_t)TCB_ATLAS_BATCH * N * 3) |
                export_f32(dir, "uv.f32", t->uv, (size_t)M * 2)))
        rc = tcb_fail(err, TCB_ERR_IO, "cannot write the step of %s", methods[k].name);
    tcb_atlas_trainer_free(t);
    tcb_atlas_model_free(m);
    return rc;
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: atlas_step_export DIR\n");
        return 2;
    }
    tcb_error err = {0};
    tcb_sequence seq = {0};
    int rc = make_sequence(&seq, &err);
    for (int k = 0; !rc && k < (int)(sizeof methods / sizeof *methods); k++)
        rc = export_step(argv[1], k, &seq, &err);
    if (rc) fprintf(stderr, "atlas_step_export: %s\n", err.msg);
    tcb_sequence_free(&seq);
    return rc ? 1 : 0;
}
