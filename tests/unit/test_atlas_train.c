/* Atlas training and the three registered methods: Adam against a
 * hand-computed update, the lr schedule, loss decrease and reconstruction
 * on a short synthetic sequence, transfer, determinism, save/load, params. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "neural/adam.h"
#include "methods/atlas/train.h"
#include "tcb/fsutil.h"
#include "tcb/metrics.h"
#include "tcb/registry.h"
#include "tcb/synth.h"
#include "testutil.h"

/* ---- Adam ---------------------------------------------------------------- */

/* By hand, lr 0.1, β 0.9/0.999:
 * step 1, g = (0.5, 0): m = (0.05, 0), v = (2.5e-4, 0), bias corrections
 *   0.1 and 0.001 → p −= 0.1/0.1 · 0.05 / (√2.5e-4/√0.001 + 1e-8) = 0.1
 *   for p0 (p1 unchanged: m = 0).
 * step 2, g = (−1, 3): m = (−0.055, 0.3), v = (1.24975e-3, 9e-3),
 *   corrections 0.19 and 0.001999 → p0 += 0.1/0.19 · 0.055 / √(1.24975e-3/0.001999)
 *   = 0.0366104, p1 −= 0.1/0.19 · 0.3 / √(9e-3/0.001999) = 0.0744137. */
static void test_adam_two_steps(void **state)
{
    (void)state;
    tcb_adam a;
    tcb_error err = {0};
    assert_int_equal(tcb_adam_init(&a, 2, &err), TCB_OK);
    float p[2] = {1, -2}, g1[2] = {0.5f, 0}, g2[2] = {-1, 3};
    tcb_adam_step(&a, p, g1, 0.1);
    assert_near(p[0], 0.9, 1e-6);
    assert_near(p[1], -2.0, 0);
    tcb_adam_step(&a, p, g2, 0.1);
    assert_near(p[0], 0.9366103542405653, 1e-6);
    assert_near(p[1], -2.0744136820059964, 1e-6);
    tcb_adam_free(&a);
}

static void test_lr_schedule(void **state)
{
    (void)state;
    assert_near(tcb_lr_at(1e-3, 0, 200000), 1e-3, 0);
    assert_near(tcb_lr_at(1e-3, 159999, 200000), 1e-3, 0);
    assert_near(tcb_lr_at(1e-3, 160000, 200000), 1e-4, 1e-18);
    assert_near(tcb_lr_at(1e-3, 179999, 200000), 1e-4, 1e-18);
    assert_near(tcb_lr_at(1e-3, 180000, 200000), 1e-5, 1e-18);
    assert_near(tcb_lr_at(1e-3, 199999, 200000), 1e-5, 1e-18);
}

/* ---- a short synthetic sequence ------------------------------------------ */

static tcb_sequence make_seq(void)
{
    tcb_sequence s;
    tcb_error err = {0};
    assert_int_equal(tcb_synth_generate("quadruped_walk", 1, 6, &s, &err), TCB_OK);
    assert_int_equal(tcb_sequence_normalize(&s, TCB_NORM_FIRST_FRAME, &err), TCB_OK);
    assert_int_equal(tcb_sequence_sample_pools(&s, 600, 1, &err), TCB_OK);
    s.input_points = 300, s.draw_with_replacement = 0;
    return s;
}

static double mean(const double *x, int n)
{
    double s = 0;
    for (int k = 0; k < n; k++) s += x[k];
    return s / n;
}

#define TRAIN_ITERS 300

/* The tiny preset's network trained directly with each method's loss: the
 * loss of the last 20 iterations must be under half that of the first 20
 * (measured ≈ 0.1). */
static void test_loss_decreases(void **state)
{
    (void)state;
    tcb_sequence s = make_seq();
    const tcb_atlas_loss losses[] = {TCB_ATLAS_LOSS_CHAMFER, TCB_ATLAS_LOSS_DSR, TCB_ATLAS_LOSS_METRIC};
    for (int k = 0; k < 3; k++) {
        tcb_error err = {0};
        tcb_atlas_model *m;
        assert_int_equal(tcb_atlas_model_create(32, 4, &m, &err), TCB_OK);
        tcb_rng rng;
        tcb_rng_seed(&rng, 3);
        tcb_atlas_model_init(m, &rng);
        tcb_atlas_train_cfg cfg = {.loss = losses[k], .M = 200, .iterations = TRAIN_ITERS, .lr = 1e-3,
                                   .alpha_mc = 0.1, .alpha_sciso = 0.001, .delta = 1, .divergence = 1e4};
        tcb_atlas_trainer *t;
        assert_int_equal(tcb_atlas_trainer_create(&cfg, m, &s, 7, &t, &err), TCB_OK);
        double loss[TRAIN_ITERS];
        for (int it = 0; it < TRAIN_ITERS; it++) {
            assert_int_equal(tcb_atlas_train_step(t, &s, &loss[it], &err), TCB_OK);
            assert_true(isfinite(loss[it]));
        }
        double first = mean(loss, 20), last = mean(loss + TRAIN_ITERS - 20, 20);
        print_message("loss %d: %.4f over the first 20 iterations, %.4f over the last 20\n", k, first, last);
        if (!(last < 0.5 * first)) fail_msg("loss %d: %g → %g", k, first, last);
        tcb_atlas_trainer_free(t);
        tcb_atlas_model_free(m);
    }
    tcb_sequence_free(&s);
}

/* ---- the registered methods ---------------------------------------------- */

static void *fitted(const char *name, const char *params, const tcb_sequence *s, uint64_t seed)
{
    const tcb_method_ops *ops = tcb_registry_find(name);
    assert_non_null(ops);
    void *self = NULL;
    tcb_error err = {0};
    assert_int_equal(ops->create(params, &self, &err), TCB_OK);
    tcb_fit_ctx ctx = {.seed = seed, .n_threads = 1, .work_dir = "."};
    int rc = ops->fit(self, s, &ctx, &err);
    if (rc) fail_msg("%s fit: %s", name, err.msg);
    return self;
}

/* transfer(i, j) of frame i's GT vertices: finite points. Returns out. */
static float *transfer(const tcb_method_ops *ops, void *self, const tcb_sequence *s, int i, int j)
{
    float *out = malloc((size_t)s->n_verts * 3 * sizeof *out);
    assert_non_null(out);
    tcb_rng rng;
    tcb_rng_seed(&rng, 11);
    tcb_error err = {0};
    int rc = ops->transfer(self, s, i, j, tcb_seq_frame(s, i), s->n_verts, out, &rng, &err);
    if (rc) fail_msg("transfer: %s", err.msg);
    for (int k = 0; k < 3 * s->n_verts; k++) assert_true(isfinite(out[k]));
    return out;
}

static double recon_cd(const tcb_method_ops *ops, void *self, const tcb_sequence *s, int i, int j, int f)
{
    tcb_rng rng;
    tcb_rng_seed(&rng, 11);
    tcb_error err = {0};
    float *pts;
    int n;
    assert_int_equal(ops->reconstruct(self, s, i, j, f, &rng, &pts, &n, &err), TCB_OK);
    double cd;
    assert_int_equal(tcb_chamfer(pts, n, tcb_seq_frame(s, f), s->n_verts, &cd, &err), TCB_OK);
    free(pts);
    return cd;
}

/* Each method with its tiny preset (300 iterations on 6 synthetic frames):
 * the reconstruction's Chamfer distance to the GT vertices drops from
 * > 0.3 untrained to < 0.08 (measured for mca: 0.77 → 0.033; squared
 * distances in units of the first frame's largest extent). */
static void test_methods_fit_eval(void **state)
{
    (void)state;
    tcb_sequence s = make_seq();
    const char *names[] = {"atlasnet", "dsr", "mca"};
    for (int k = 0; k < 3; k++) {
        const tcb_method_ops *ops = tcb_registry_find(names[k]);
        void *fresh = fitted(names[k], "{\"preset\": \"tiny\", \"iterations\": 1}", &s, 5);
        void *self = fitted(names[k], "{\"preset\": \"tiny\"}", &s, 5);
        double cd0 = recon_cd(ops, fresh, &s, 0, 1, 0), cd = recon_cd(ops, self, &s, 0, 1, 0);
        double cd1 = recon_cd(ops, self, &s, 0, 1, 1);
        print_message("%s: reconstruction CD %.3f untrained, %.3f / %.3f trained\n", names[k], cd0, cd, cd1);
        if (!(cd0 > 0.3 && cd < 0.08 && cd1 < 0.08))
            fail_msg("%s: CD untrained %g, trained %g and %g", names[k], cd0, cd, cd1);
        free(transfer(ops, self, &s, 0, 1));
        free(transfer(ops, self, &s, 3, 1));
        ops->destroy(fresh);
        ops->destroy(self);
    }
    tcb_sequence_free(&s);
}

/* C 8, P 2, initialised from seed 3. */
static tcb_atlas_model *small_model(void)
{
    tcb_atlas_model *m;
    tcb_error err = {0};
    assert_int_equal(tcb_atlas_model_create(8, 2, &m, &err), TCB_OK);
    tcb_rng rng;
    tcb_rng_seed(&rng, 3);
    tcb_atlas_model_init(m, &rng);
    return m;
}

/* A NaN weight stops training with TCB_ERR_NUMERIC naming the iteration. */
static void test_nan_is_numeric(void **state)
{
    (void)state;
    tcb_sequence s = make_seq();
    tcb_error err = {0};
    tcb_atlas_model *m = small_model();
    tcb_atlas_train_cfg cfg = {.loss = TCB_ATLAS_LOSS_CHAMFER, .M = 20, .iterations = 10, .lr = 1e-3,
                               .delta = 1, .divergence = 1e4};
    tcb_atlas_trainer *t;
    assert_int_equal(tcb_atlas_trainer_create(&cfg, m, &s, 7, &t, &err), TCB_OK);
    double loss;
    assert_int_equal(tcb_atlas_train_step(t, &s, &loss, &err), TCB_OK);
    m->params[m->nparams - 1] = NAN; /* the last decoder's output bias */
    assert_int_equal(tcb_atlas_train_step(t, &s, &loss, &err), TCB_ERR_NUMERIC);
    assert_non_null(strstr(err.msg, "iteration 1"));
    tcb_atlas_trainer_free(t);
    tcb_atlas_model_free(m);
    tcb_sequence_free(&s);
}

/* pairs: neighbors keeps |a − b| ≤ delta; random reaches farther frames
 * (Table 2's switch), and the method param selects it. */
static void test_pairs_modes(void **state)
{
    (void)state;
    tcb_sequence s = make_seq();
    tcb_error err = {0};
    tcb_atlas_model *m = small_model();
    for (int mode = 0; mode < 2; mode++) {
        tcb_atlas_train_cfg cfg = {.loss = TCB_ATLAS_LOSS_CHAMFER, .M = 20, .iterations = 40, .lr = 1e-3,
                                   .pairs = mode ? TCB_PAIRS_RANDOM : TCB_PAIRS_NEIGHBORS, .delta = 1,
                                   .divergence = 1e4};
        tcb_atlas_trainer *t;
        assert_int_equal(tcb_atlas_trainer_create(&cfg, m, &s, 7, &t, &err), TCB_OK);
        int far = 0;
        for (int it = 0; it < 40; it++) {
            double loss;
            assert_int_equal(tcb_atlas_train_step(t, &s, &loss, &err), TCB_OK);
            for (int p = 0; p < TCB_ATLAS_BATCH; p += 2) {
                int gap = abs(t->frames[p] - t->frames[p + 1]);
                assert_true(gap >= 1);
                far += gap > 1;
            }
        }
        if (mode) assert_true(far > 0);
        else assert_int_equal(far, 0);
        tcb_atlas_trainer_free(t);
    }
    tcb_atlas_train_cfg bad = {.loss = TCB_ATLAS_LOSS_CHAMFER, .M = 20, .iterations = 4, .lr = 1e-3,
                               .pairs = TCB_PAIRS_WITHIN_SEQ, .delta = 1, .divergence = 1e4};
    tcb_atlas_trainer *t = NULL;
    assert_int_equal(tcb_atlas_trainer_create(&bad, m, &s, 7, &t, &err), TCB_ERR_INPUT);
    void *self = NULL;
    assert_int_equal(tcb_registry_find("mca")->create("{\"pairs\": \"random\"}", &self, &err), TCB_OK);
    tcb_registry_find("mca")->destroy(self);
    tcb_atlas_model_free(m);
    tcb_sequence_free(&s);
}

static char *saved(const tcb_method_ops *ops, void *self, const char *dir, const char *name, size_t *len)
{
    char path[TCB_PATH_MAX], *buf;
    tcb_error err = {0};
    snprintf(path, sizeof path, "%s/%s", dir, name);
    assert_int_equal(ops->save(self, path, &err), TCB_OK);
    assert_int_equal(tcb_read_file(path, &buf, len, &err), TCB_OK);
    return buf;
}

/* All three methods train and transfer; the same seed gives the same
 * weights bit for bit, another seed others, and so does another method's
 * loss (the table's loss is wired in); a loaded checkpoint transfers
 * exactly as the fitted model. */
static void test_methods_seed_and_checkpoint(void **state)
{
    const char *dir = *state;
    tcb_sequence s = make_seq();
    const char *params = "{\"preset\": \"tiny\", \"iterations\": 15}";
    const char *names[] = {"atlasnet", "dsr", "mca"};
    char *prev = NULL;
    for (int k = 0; k < 3; k++) {
        const tcb_method_ops *ops = tcb_registry_find(names[k]);
        void *a = fitted(names[k], params, &s, 21), *b = fitted(names[k], params, &s, 21);
        void *c = fitted(names[k], params, &s, 22);
        size_t la, lb, lc;
        char *fa = saved(ops, a, dir, "a", &la), *fb = saved(ops, b, dir, "b", &lb), *fc = saved(ops, c, dir, "c", &lc);
        assert_true(la == lb && la == lc);
        assert_memory_equal(fa, fb, la);
        /* The file ends with the weights, which outweigh the header and
         * manifest (the seed is in the header): compare the second half. */
        assert_memory_not_equal(fa + la / 2, fc + la / 2, la - la / 2);
        if (prev) assert_memory_not_equal(prev + la / 2, fa + la / 2, la - la / 2);

        void *d = NULL;
        tcb_error err = {0};
        char path[TCB_PATH_MAX];
        snprintf(path, sizeof path, "%s/a", dir);
        assert_int_equal(ops->create(params, &d, &err), TCB_OK);
        assert_int_equal(ops->load(d, &s, path, &err), TCB_OK);
        float *ta = transfer(ops, a, &s, 2, 4), *td = transfer(ops, d, &s, 2, 4);
        assert_memory_equal(ta, td, (size_t)s.n_verts * 3 * sizeof *ta);
        free(ta), free(td), free(prev), free(fb), free(fc);
        prev = fa;
        ops->destroy(a), ops->destroy(b), ops->destroy(c), ops->destroy(d);
    }
    free(prev);
    tcb_sequence_free(&s);
}

/* A checkpoint of another network size or a foreign file is refused. */
static void test_load_rejects(void **state)
{
    const char *dir = *state;
    tcb_sequence s = make_seq();
    const tcb_method_ops *ops = tcb_registry_find("mca");
    void *a = fitted("mca", "{\"preset\": \"tiny\", \"iterations\": 1}", &s, 1), *b = NULL;
    size_t len;
    free(saved(ops, a, dir, "ck", &len));
    char path[TCB_PATH_MAX], junk[TCB_PATH_MAX];
    snprintf(path, sizeof path, "%s/ck", dir);
    tcb_error err = {0};
    assert_int_equal(ops->create("{\"preset\": \"tiny\", \"latent\": 16}", &b, &err), TCB_OK);
    assert_int_equal(ops->load(b, &s, path, &err), TCB_ERR_INPUT);
    tu_write_text(dir, "junk", "not a checkpoint at all, clearly", junk, sizeof junk);
    assert_int_equal(ops->load(b, &s, junk, &err), TCB_ERR_INPUT);
    ops->destroy(a), ops->destroy(b);
    tcb_sequence_free(&s);
}

static void test_bad_params(void **state)
{
    (void)state;
    const char *bad[] = {
        "{\"presett\": \"tiny\"}", "{\"preset\": \"huge\"}", "{\"latent\": 0}",
        "{\"patches\": 3, \"uv_samples\": 100}", "{\"iterations\": 0}", "{\"lr\": \"fast\"}",
        "{\"delta\": 0}", "{\"alpha_mc\": -1}", "{\"pairs\": \"within_seq\"}", "[1]",
    };
    const char *names[] = {"atlasnet", "dsr", "mca"};
    for (int k = 0; k < 3; k++)
        for (size_t b = 0; b < sizeof bad / sizeof bad[0]; b++) {
            void *self = NULL;
            tcb_error err = {0};
            assert_int_equal(tcb_registry_find(names[k])->create(bad[b], &self, &err), TCB_ERR_INPUT);
            assert_null(self);
            assert_non_null(strstr(err.msg, names[k]));
        }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_adam_two_steps),
        cmocka_unit_test(test_pairs_modes),
        cmocka_unit_test(test_lr_schedule),
        cmocka_unit_test(test_loss_decreases),
        cmocka_unit_test(test_methods_fit_eval),
        cmocka_unit_test(test_nan_is_numeric),
        cmocka_unit_test_setup_teardown(test_methods_seed_and_checkpoint, tu_setup_tmpdir, tu_teardown_tmpdir),
        cmocka_unit_test_setup_teardown(test_load_rejects, tu_setup_tmpdir, tu_teardown_tmpdir),
        cmocka_unit_test(test_bad_params),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
