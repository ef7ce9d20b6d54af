/* Atlas training checkpoints and divergence: a training stopped and resumed
 * from its checkpoint ends bit-identical to an uninterrupted one, both
 * through the trainer and through a method's fit; damaged or foreign
 * checkpoints are refused with the reason and leave the trainer untouched;
 * an exploding loss stops training as TCB_ERR_NUMERIC. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "methods/atlas/train.h"
#include "methods/atlas/train_ckpt.h"
#include "tcb/fsutil.h"
#include "tcb/registry.h"
#include "tcb/synth.h"
#include "testutil.h"

#define SEED 5
#define ITERS 24

static tcb_sequence make_seq(void)
{
    tcb_sequence s;
    tcb_error err = {0};
    assert_int_equal(tcb_synth_generate("humanoid_jacks", 1, 5, &s, &err), TCB_OK);
    assert_int_equal(tcb_sequence_normalize(&s, TCB_NORM_FIRST_FRAME, &err), TCB_OK);
    assert_int_equal(tcb_sequence_sample_pools(&s, 500, 1, &err), TCB_OK);
    s.input_points = 200, s.draw_with_replacement = 0;
    return s;
}

/* The mca method's tiny preset with ITERS iterations, as a trainer config. */
static const tcb_atlas_train_cfg tiny_mca = {
    .loss = TCB_ATLAS_LOSS_METRIC, .M = 200, .iterations = ITERS, .lr = 1e-3, .alpha_mc = 0.1,
    .alpha_sciso = 0.001, .delta = 1, .divergence = 1e4};
#define TINY_C 32
#define TINY_P 4

/* A model initialised as the methods do: stream (seed, "atlas/init"). */
static tcb_atlas_model *new_model(int C, uint64_t seed)
{
    tcb_atlas_model *m;
    tcb_error err = {0};
    assert_int_equal(tcb_atlas_model_create(C, TINY_P, &m, &err), TCB_OK);
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, seed, "atlas/init");
    tcb_atlas_model_init(m, &rng);
    return m;
}

static tcb_atlas_trainer *new_trainer(const tcb_atlas_train_cfg *cfg, tcb_atlas_model *m,
                                      const tcb_sequence *s)
{
    tcb_atlas_trainer *t;
    tcb_error err = {0};
    assert_int_equal(tcb_atlas_trainer_create(cfg, m, s, SEED, &t, &err), TCB_OK);
    return t;
}

static void steps(tcb_atlas_trainer *t, const tcb_sequence *s, long long until)
{
    tcb_error err = {0};
    double loss;
    while (t->it < until)
        if (tcb_atlas_train_step(t, s, &loss, &err)) fail_msg("step %lld: %s", t->it, err.msg);
}

static void join(char *out, const char *dir, const char *name)
{
    tcb_error err = {0};
    assert_int_equal(tcb_path_join(out, TCB_PATH_MAX, &err, "%s/%s", dir, name), TCB_OK);
}

static void ckpt_path(const char *dir, char *out) { join(out, dir, TCB_ATLAS_TRAIN_CKPT); }

/* Stop at 10 of 24, save, continue in a fresh trainer whose model starts
 * from other weights: weights, moments and random stream match, and the
 * training time stamp comes back. */
static void test_trainer_resume_bit_identical(void **state)
{
    const char *dir = *state;
    tcb_sequence s = make_seq();
    char path[TCB_PATH_MAX];
    ckpt_path(dir, path);
    tcb_atlas_model *ma = new_model(TINY_C, SEED), *mb = new_model(TINY_C, SEED), *mc = new_model(TINY_C, 99);
    tcb_atlas_trainer *ta = new_trainer(&tiny_mca, ma, &s), *tb = new_trainer(&tiny_mca, mb, &s);
    steps(ta, &s, ITERS);
    steps(tb, &s, 10);
    tcb_error err = {0};
    assert_int_equal(tcb_atlas_train_ckpt_save(tb, &s, SEED, 12.5, path, &err), TCB_OK);
    tcb_atlas_trainer_free(tb);

    tcb_atlas_trainer *tc = new_trainer(&tiny_mca, mc, &s);
    double seconds = -1;
    assert_int_equal(tcb_atlas_train_ckpt_load(tc, &s, SEED, path, &seconds, &err), TCB_OK);
    assert_int_equal(tc->it, 10);
    assert_true(seconds == 12.5);
    steps(tc, &s, ITERS);
    size_t bytes = ma->nparams * sizeof(float);
    assert_memory_equal(ma->params, mc->params, bytes);
    assert_memory_equal(ta->adam.m, tc->adam.m, bytes);
    assert_memory_equal(ta->adam.v, tc->adam.v, bytes);
    assert_memory_equal(ta->rng.s, tc->rng.s, sizeof ta->rng.s);
    assert_int_equal(ta->adam.t, tc->adam.t);
    tcb_atlas_trainer_free(ta), tcb_atlas_trainer_free(tc);
    tcb_atlas_model_free(ma), tcb_atlas_model_free(mb), tcb_atlas_model_free(mc);
    tcb_sequence_free(&s);
}

/* Collects log lines. */
typedef struct log_buf {
    char text[4096];
} log_buf;

static void collect(void *ctx, tcb_log_level level, const char *msg)
{
    (void)level;
    log_buf *b = ctx;
    size_t used = strlen(b->text);
    snprintf(b->text + used, sizeof b->text - used, "%s\n", msg);
}

/* Fits mca in `work` and returns its saved model; *resumed_s gets what the
 * fit reports through ctx->resumed_fit_s. */
static char *fit_and_save(const char *params, const tcb_sequence *s, const char *work, log_buf *log,
                          size_t *len, double *resumed_s)
{
    const tcb_method_ops *ops = tcb_registry_find("mca");
    void *self = NULL;
    tcb_error err = {0};
    assert_int_equal(ops->create(params, &self, &err), TCB_OK);
    *resumed_s = -1;
    tcb_fit_ctx ctx = {.seed = SEED, .n_threads = 1, .work_dir = work, .reporter = {.log = collect, .ctx = log},
                       .resumed_fit_s = resumed_s};
    if (ops->fit(self, s, &ctx, &err)) fail_msg("fit: %s", err.msg);
    char path[TCB_PATH_MAX], *buf;
    join(path, work, "model.ckpt");
    assert_int_equal(ops->save(self, path, &err), TCB_OK);
    assert_int_equal(tcb_read_file(path, &buf, len, &err), TCB_OK);
    ops->destroy(self);
    return buf;
}

/* The method's fit: uninterrupted in one directory; in another, a training
 * state at iteration 10 is left where a killed fit would have left it, and
 * the fit continues from it (its log says so) to the same weights, reports
 * the state's training time as resumed, then removes it. A corrupt state is
 * reported and training starts over. */
static void test_fit_resumes(void **state)
{
    const char *dir = *state;
    tcb_sequence s = make_seq();
    const char *params = "{\"preset\": \"tiny\", \"iterations\": 24, \"checkpoint_every\": 5}";
    char full[TCB_PATH_MAX], killed[TCB_PATH_MAX], path[TCB_PATH_MAX];
    tcb_error err = {0};
    join(full, dir, "full");
    join(killed, dir, "killed");
    assert_int_equal(tcb_mkdirs(full, &err), TCB_OK);
    assert_int_equal(tcb_mkdirs(killed, &err), TCB_OK);
    log_buf log_full = {""}, log_killed = {""}, log_corrupt = {""};
    size_t la, lb, lc;
    double resumed;
    char *a = fit_and_save(params, &s, full, &log_full, &la, &resumed);
    ckpt_path(full, path);
    assert_false(tcb_is_file(path));
    assert_null(strstr(log_full.text, "resuming"));
    assert_true(resumed == 0);

    tcb_atlas_model *m = new_model(TINY_C, SEED);
    tcb_atlas_trainer *t = new_trainer(&tiny_mca, m, &s);
    steps(t, &s, 10);
    ckpt_path(killed, path);
    assert_int_equal(tcb_atlas_train_ckpt_save(t, &s, SEED, 1234.5, path, &err), TCB_OK);
    char *b = fit_and_save(params, &s, killed, &log_killed, &lb, &resumed);
    assert_non_null(strstr(log_killed.text, "resuming training at iteration 10"));
    assert_true(resumed == 1234.5);
    assert_false(tcb_is_file(path));
    assert_int_equal(la, lb);
    assert_memory_equal(a, b, la);

    char junk[TCB_PATH_MAX];
    tu_write_text(killed, TCB_ATLAS_TRAIN_CKPT, "TCBATRN2 but nothing after it", junk, sizeof junk);
    char *c = fit_and_save(params, &s, killed, &log_corrupt, &lc, &resumed);
    assert_non_null(strstr(log_corrupt.text, "not resumed"));
    assert_true(resumed == 0);
    assert_int_equal(la, lc);
    assert_memory_equal(a, c, la);
    free(a), free(b), free(c);
    tcb_atlas_trainer_free(t);
    tcb_atlas_model_free(m);
    tcb_sequence_free(&s);
}

/* load must fail with `want` in the message and leave t as it was. */
static void expect_refused(tcb_atlas_trainer *t, const tcb_sequence *s, const char *path, const char *want)
{
    size_t bytes = t->model->nparams * sizeof(float);
    float *before = malloc(bytes);
    assert_non_null(before);
    memcpy(before, t->model->params, bytes);
    long long it = t->it;
    tcb_error err = {0};
    double seconds = -1;
    assert_int_equal(tcb_atlas_train_ckpt_load(t, s, SEED, path, &seconds, &err), TCB_ERR_INPUT);
    assert_true(seconds == -1);
    if (!strstr(err.msg, want)) fail_msg("expected '%s' in: %s", want, err.msg);
    assert_non_null(strstr(err.msg, path));
    assert_memory_equal(before, t->model->params, bytes);
    assert_int_equal(it, t->it);
    free(before);
}

static void rewrite(const char *path, const char *buf, size_t len)
{
    tcb_error err = {0};
    assert_int_equal(tcb_write_file_atomic(path, buf, len, &err), TCB_OK);
}

static void test_damaged_and_foreign_refused(void **state)
{
    const char *dir = *state;
    tcb_sequence s = make_seq();
    char path[TCB_PATH_MAX], *buf;
    size_t len;
    tcb_error err = {0};
    ckpt_path(dir, path);
    tcb_atlas_model *m = new_model(TINY_C, SEED);
    tcb_atlas_trainer *t = new_trainer(&tiny_mca, m, &s);
    steps(t, &s, 3);
    assert_int_equal(tcb_atlas_train_ckpt_save(t, &s, SEED, 60, path, &err), TCB_OK);
    assert_int_equal(tcb_read_file(path, &buf, &len, &err), TCB_OK);
    tcb_atlas_trainer_free(t);
    t = new_trainer(&tiny_mca, m, &s);

    rewrite(path, buf, len - 1);
    expect_refused(t, &s, path, "truncated");
    buf[len / 2] ^= 1;
    rewrite(path, buf, len);
    expect_refused(t, &s, path, "checksum");
    buf[len / 2] ^= 1;
    memcpy(buf, "TCBATLS1", 8);
    rewrite(path, buf, len);
    expect_refused(t, &s, path, "magic");
    memcpy(buf, "TCBATRN1", 8); /* the format before training times were kept */
    rewrite(path, buf, len);
    expect_refused(t, &s, path, "magic");
    memcpy(buf, "TCBATRN2", 8); /* the format before the pairs mode was kept */
    rewrite(path, buf, len);
    expect_refused(t, &s, path, "magic");
    memcpy(buf, "TCBATRN3", 8); /* the format before the sequence's fingerprint was kept */
    rewrite(path, buf, len);
    expect_refused(t, &s, path, "magic");
    memcpy(buf, "TCBATRN4", 8);
    rewrite(path, buf, len);
    double seconds;
    assert_int_equal(tcb_atlas_train_ckpt_load(t, &s, SEED, path, &seconds, &err), TCB_OK);
    assert_int_equal(t->it, 3);
    assert_true(seconds == 60);
    assert_int_equal(tcb_atlas_train_ckpt_save(t, &s, SEED, -1, path, &err), TCB_OK);
    expect_refused(t, &s, path, "not a duration");
    tcb_atlas_trainer_free(t);

    tcb_atlas_train_cfg longer = tiny_mca;
    longer.iterations = 2 * ITERS;
    t = new_trainer(&longer, m, &s);
    expect_refused(t, &s, path, "iterations is 24, this training has 48");
    tcb_atlas_trainer_free(t);
    tcb_atlas_model *wide = new_model(2 * TINY_C, SEED);
    t = new_trainer(&tiny_mca, wide, &s);
    expect_refused(t, &s, path, "latent is 32, this training has 64");
    tcb_atlas_trainer_free(t);
    /* Another sequence of the same sizes: the fingerprint tells them apart. */
    tcb_sequence other = make_seq();
    other.pools[0] += 1e-3f;
    t = new_trainer(&tiny_mca, m, &other);
    expect_refused(t, &other, path, "sequence fingerprint is ");
    tcb_atlas_trainer_free(t);
    tcb_sequence_free(&other);
    tcb_atlas_model_free(wide), tcb_atlas_model_free(m);
    free(buf);
    tcb_sequence_free(&s);
}

/* A loss that jumps far above the first one is divergence, reported as
 * TCB_ERR_NUMERIC with the numbers; with the test off training goes on. */
static void test_divergence_stops(void **state)
{
    (void)state;
    tcb_sequence s = make_seq();
    for (int guard = 1; guard >= 0; guard--) {
        tcb_atlas_train_cfg cfg = tiny_mca;
        cfg.divergence = guard ? 1e4 : 0;
        tcb_atlas_model *m = new_model(TINY_C, SEED);
        tcb_atlas_trainer *t = new_trainer(&cfg, m, &s);
        steps(t, &s, 1);
        for (int k = 1; k <= 3; k++) m->params[m->nparams - k] += 1e3f; /* the last patch's output bias */
        tcb_error err = {0};
        double loss;
        int rc = tcb_atlas_train_step(t, &s, &loss, &err);
        if (guard) {
            assert_int_equal(rc, TCB_ERR_NUMERIC);
            assert_non_null(strstr(err.msg, "diverged"));
            assert_non_null(strstr(err.msg, "iteration 1"));
            assert_int_equal(t->it, 1);
        } else {
            assert_int_equal(rc, TCB_OK);
            assert_true(loss > 1e4 * t->loss0);
        }
        tcb_atlas_trainer_free(t);
        tcb_atlas_model_free(m);
    }
    tcb_sequence_free(&s);
}

int main(void)
{
    /* Bits are reproducible per thread count: the trainers made here by hand
     * must run with the fits' n_threads = 1. */
    omp_set_num_threads(1);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_trainer_resume_bit_identical, tu_setup_tmpdir, tu_teardown_tmpdir),
        cmocka_unit_test_setup_teardown(test_fit_resumes, tu_setup_tmpdir, tu_teardown_tmpdir),
        cmocka_unit_test_setup_teardown(test_damaged_and_foreign_refused, tu_setup_tmpdir, tu_teardown_tmpdir),
        cmocka_unit_test(test_divergence_stops),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
