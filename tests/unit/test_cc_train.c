/* CC training (methods/cycle/train.c, train_ckpt.c) and the registered
 * method (cc_method.c): the loss falls on a short synthetic sequence with
 * each triplet sampling; the warm-up runs the self-reconstruction term and
 * then stops; Adam is recreated at each lr decay; a training resumed from
 * its checkpoint ends bit-identical, and damaged or foreign checkpoints
 * are refused; divergence ends the training; the method's params, save /
 * load and transfer. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "methods/cycle/train.h"
#include "methods/cycle/train_ckpt.h"
#include "tcb/fsutil.h"
#include "tcb/registry.h"
#include "tcb/synth.h"
#include "testutil.h"

#define SEED 3

static const tcb_cc_dims tiny = {16, 8, 8, 2, 0};

static tcb_sequence make_seq(void)
{
    tcb_sequence s;
    tcb_error err = {0};
    assert_int_equal(tcb_synth_generate("quadruped_walk", 1, 6, &s, &err), TCB_OK);
    assert_int_equal(tcb_sequence_normalize(&s, TCB_NORM_FIRST_FRAME, &err), TCB_OK);
    assert_int_equal(tcb_sequence_sample_pools(&s, 600, 1, &err), TCB_OK);
    s.input_points = 120, s.draw_with_replacement = 0;
    return s;
}

static tcb_cc_train_cfg make_cfg(tcb_cc_sampling sampling, long long iterations, long long warmup)
{
    tcb_cc_train_cfg c = {.sampler = tcb_cc_sampler_opts_default(), .batch = 3, .iterations = iterations,
                          .warmup = warmup, .lr = 1e-3, .divergence = 1e4};
    c.sampler.sampling = sampling, c.sampler.knn_k = 3, c.sampler.knn_points = 200;
    return c;
}

static tcb_cc_net *new_net(uint64_t seed)
{
    tcb_cc_net *n;
    tcb_error err = {0};
    assert_int_equal(tcb_cc_net_create(&tiny, &n, &err), TCB_OK);
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, seed, "cc/init");
    tcb_cc_net_init(n, &rng);
    return n;
}

static tcb_cc_trainer *new_trainer(const tcb_cc_train_cfg *cfg, tcb_cc_net *n, const tcb_sequence *s)
{
    tcb_cc_trainer *t;
    tcb_error err = {0};
    if (tcb_cc_trainer_create(cfg, n, s, SEED, &t, &err)) fail_msg("trainer: %s", err.msg);
    return t;
}

/* Steps to `until`; returns the mean loss of the last `tail` steps. */
static double steps(tcb_cc_trainer *t, const tcb_sequence *s, long long until, int tail)
{
    tcb_error err = {0};
    double loss, sum = 0;
    while (t->it < until) {
        if (tcb_cc_train_step(t, s, &loss, &err)) fail_msg("step %lld: %s", t->it, err.msg);
        if (t->it > until - tail) sum += loss;
    }
    return sum / tail;
}

/* 150 steps of each sampling after the warm-up: the cycle losses fall well
 * below where they start (a gradient pointing the wrong way, or not
 * reaching the weights, leaves them flat). */
static void test_loss_decreases(void **state)
{
    (void)state;
    tcb_sequence s = make_seq();
    for (int k = 0; k < 3; k++) {
        tcb_cc_train_cfg cfg = make_cfg((tcb_cc_sampling)k, 1000, 0);
        cfg.lr = 3e-3;
        tcb_cc_net *n = new_net(SEED);
        tcb_cc_trainer *t = new_trainer(&cfg, n, &s);
        double first = steps(t, &s, 10, 10), last = steps(t, &s, 150, 10);
        printf("sampling %s: mean loss of steps 1-10 %.4f, 141-150 %.4f\n", tcb_cc_sampling_name(k), first, last);
        if (!(last < 0.7 * first)) fail_msg("%s: loss %.4f -> %.4f", tcb_cc_sampling_name(k), first, last);
        assert_true(t->last.selfrec == 0);
        tcb_cc_trainer_free(t);
        tcb_cc_net_free(n);
    }
    tcb_sequence_free(&s);
}

/* During the warm-up the self-reconstruction term is on (and the target
 * C' differs from C), after it off. */
static void test_warmup(void **state)
{
    (void)state;
    tcb_sequence s = make_seq();
    tcb_cc_train_cfg cfg = make_cfg(TCB_CC_SAMPLE_RANDOM, 10, 3);
    tcb_cc_net *n = new_net(SEED);
    tcb_cc_trainer *t = new_trainer(&cfg, n, &s);
    for (int it = 0; it < 5; it++) {
        steps(t, &s, it + 1, 1);
        if (it < 3) {
            assert_true(t->last.selfrec > 0);
            assert_true(fabs(t->last.total - t->last.cycle.total - t->last.selfrec) < 1e-9);
        } else {
            assert_true(t->last.selfrec == 0);
            assert_true(t->last.total == t->last.cycle.total);
        }
    }
    tcb_cc_trainer_free(t);
    tcb_cc_net_free(n);
    tcb_sequence_free(&s);
}

/* 20 iterations: lr 1e-3 up to 15, 1e-4 from 16, 1e-5 from 18, and Adam
 * starts afresh at each change (its step count says so). */
static void test_adam_recreated_at_decays(void **state)
{
    (void)state;
    tcb_sequence s = make_seq();
    tcb_cc_train_cfg cfg = make_cfg(TCB_CC_SAMPLE_RANDOM, 20, 0);
    tcb_cc_net *n = new_net(SEED);
    tcb_cc_trainer *t = new_trainer(&cfg, n, &s);
    long long want[20];
    for (int it = 0; it < 20; it++) want[it] = it < 16 ? it + 1 : it < 18 ? it - 15 : it - 17;
    for (int it = 0; it < 20; it++) {
        steps(t, &s, it + 1, 1);
        assert_int_equal(t->adam.t, want[it]);
    }
    tcb_cc_trainer_free(t);
    tcb_cc_net_free(n);
    tcb_sequence_free(&s);
}

static void ckpt_path(const char *dir, char *out)
{
    tcb_error err = {0};
    assert_int_equal(tcb_path_join(out, TCB_PATH_MAX, &err, "%s/%s", dir, TCB_CC_TRAIN_CKPT), TCB_OK);
}

/* Stop at 7 of 16 (inside the warm-up of 8, so the self-reconstruction's
 * draws are in the saved stream), save, continue in a fresh trainer whose
 * network starts from other weights: weights, running statistics, moments
 * and stream match the uninterrupted training. */
static void test_resume_bit_identical(void **state)
{
    const char *dir = *state;
    tcb_sequence s = make_seq();
    char path[TCB_PATH_MAX];
    ckpt_path(dir, path);
    tcb_cc_train_cfg cfg = make_cfg(TCB_CC_SAMPLE_KNN, 16, 8);
    tcb_cc_net *na = new_net(SEED), *nb = new_net(SEED), *nc = new_net(99);
    tcb_cc_trainer *ta = new_trainer(&cfg, na, &s), *tb = new_trainer(&cfg, nb, &s);
    steps(ta, &s, 16, 1);
    steps(tb, &s, 7, 1);
    tcb_error err = {0};
    assert_int_equal(tcb_cc_train_ckpt_save(tb, &s, SEED, 12.5, path, &err), TCB_OK);
    tcb_cc_trainer_free(tb);
    tcb_cc_trainer *tc = new_trainer(&cfg, nc, &s);
    double seconds = -1;
    assert_int_equal(tcb_cc_train_ckpt_load(tc, &s, SEED, path, &seconds, &err), TCB_OK);
    assert_int_equal(tc->it, 7);
    assert_true(seconds == 12.5);
    steps(tc, &s, 16, 1);
    size_t bytes = na->nparams * sizeof(float);
    assert_memory_equal(na->params, nc->params, bytes);
    assert_memory_equal(na->buffers, nc->buffers, na->nbuffers * sizeof(float));
    assert_memory_equal(ta->adam.m, tc->adam.m, bytes);
    assert_memory_equal(ta->adam.v, tc->adam.v, bytes);
    assert_memory_equal(ta->rng.s, tc->rng.s, sizeof ta->rng.s);
    tcb_cc_trainer_free(ta), tcb_cc_trainer_free(tc);
    tcb_cc_net_free(na), tcb_cc_net_free(nb), tcb_cc_net_free(nc);
    tcb_sequence_free(&s);
}

/* load fails with `want` and the path in the message, t unchanged. */
static void expect_refused(tcb_cc_trainer *t, const tcb_sequence *s, const char *path, const char *want)
{
    size_t bytes = t->net->nparams * sizeof(float);
    float *before = malloc(bytes);
    assert_non_null(before);
    memcpy(before, t->net->params, bytes);
    long long it = t->it;
    tcb_error err = {0};
    double seconds = -1;
    assert_int_equal(tcb_cc_train_ckpt_load(t, s, SEED, path, &seconds, &err), TCB_ERR_INPUT);
    assert_true(seconds == -1);
    if (!strstr(err.msg, want)) fail_msg("expected '%s' in: %s", want, err.msg);
    assert_non_null(strstr(err.msg, path));
    assert_memory_equal(before, t->net->params, bytes);
    assert_int_equal(it, t->it);
    free(before);
}

static void test_damaged_and_foreign_refused(void **state)
{
    const char *dir = *state;
    tcb_sequence s = make_seq();
    char path[TCB_PATH_MAX], *buf;
    size_t len;
    tcb_error err = {0};
    ckpt_path(dir, path);
    tcb_cc_train_cfg cfg = make_cfg(TCB_CC_SAMPLE_RANDOM, 12, 2);
    tcb_cc_net *n = new_net(SEED);
    tcb_cc_trainer *t = new_trainer(&cfg, n, &s);
    steps(t, &s, 3, 1);
    assert_int_equal(tcb_cc_train_ckpt_save(t, &s, SEED, 60, path, &err), TCB_OK);
    assert_int_equal(tcb_read_file(path, &buf, &len, &err), TCB_OK);
    tcb_cc_trainer_free(t);
    t = new_trainer(&cfg, n, &s);
    assert_int_equal(tcb_write_file_atomic(path, buf, len - 1, &err), TCB_OK);
    expect_refused(t, &s, path, "truncated");
    buf[len / 2] ^= 1;
    assert_int_equal(tcb_write_file_atomic(path, buf, len, &err), TCB_OK);
    expect_refused(t, &s, path, "checksum");
    buf[len / 2] ^= 1;
    memcpy(buf, "TCBATRN2", 8); /* an atlas training's */
    assert_int_equal(tcb_write_file_atomic(path, buf, len, &err), TCB_OK);
    expect_refused(t, &s, path, "not a cc training checkpoint");
    memcpy(buf, "TCBCCTR1", 8); /* the format before the sequence's fingerprint was kept */
    assert_int_equal(tcb_write_file_atomic(path, buf, len, &err), TCB_OK);
    expect_refused(t, &s, path, "not a cc training checkpoint");
    memcpy(buf, "TCBCCTR2", 8);
    assert_int_equal(tcb_write_file_atomic(path, buf, len, &err), TCB_OK);
    tcb_cc_trainer_free(t);
    tcb_cc_train_cfg other = make_cfg(TCB_CC_SAMPLE_KNN, 12, 2);
    t = new_trainer(&other, n, &s);
    expect_refused(t, &s, path, "sampling is 0, this training has 1");
    tcb_cc_trainer_free(t);
    free(buf);
    tcb_cc_net_free(n);
    tcb_sequence_free(&s);
}

/* A loss far above the first one is divergence (TCB_ERR_NUMERIC naming
 * the iteration); with the test off training goes on. */
static void test_divergence_stops(void **state)
{
    (void)state;
    tcb_sequence s = make_seq();
    for (int guard = 1; guard >= 0; guard--) {
        tcb_cc_train_cfg cfg = make_cfg(TCB_CC_SAMPLE_RANDOM, 10, 0);
        cfg.divergence = guard ? 1.5 : 0;
        tcb_cc_net *n = new_net(SEED);
        tcb_cc_trainer *t = new_trainer(&cfg, n, &s);
        steps(t, &s, 1, 1);
        /* the last meta layer's conv bias: every output saturates at ±2 */
        tcb_linear *conv = &n->p.meta[n->n_meta - 1].conv;
        for (int k = 0; k < 3; k++) conv->b[k] = k % 2 ? 50.0f : -50.0f;
        tcb_error err = {0};
        double loss;
        int rc = tcb_cc_train_step(t, &s, &loss, &err);
        if (guard) {
            assert_int_equal(rc, TCB_ERR_NUMERIC);
            assert_non_null(strstr(err.msg, "diverged"));
            assert_non_null(strstr(err.msg, "iteration 1"));
            assert_int_equal(t->it, 1);
        } else {
            assert_int_equal(rc, TCB_OK);
        }
        tcb_cc_trainer_free(t);
        tcb_cc_net_free(n);
    }
    tcb_sequence_free(&s);
}

/* ---- the registered method ---- */

static void *create_ok(const char *params)
{
    const tcb_method_ops *ops = tcb_registry_find("cc");
    assert_non_null(ops);
    void *self = NULL;
    tcb_error err = {0};
    if (ops->create(params, &self, &err)) fail_msg("create %s: %s", params, err.msg);
    return self;
}

static void test_params_refused(void **state)
{
    (void)state;
    const tcb_method_ops *ops = tcb_registry_find("cc");
    static const char *const bad[][2] = {
        {"{\"sampling\": \"knnn\"}", "sampling"}, {"{\"preset\": \"huge\"}", "preset"},
        {"{\"lr\": 0}", "lr"},                    {"{\"batch\": 1}", "batch"},
        {"{\"latent\": 7}", "latent"},            {"{\"warmup\": 2}", "warmup"},
        {"{\"readout\": \"mesh\"}", "readout"},   {"{\"alpha\": 1}", "alpha"},
    };
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        void *self = NULL;
        tcb_error err = {0};
        assert_int_equal(ops->create(bad[k][0], &self, &err), TCB_ERR_INPUT);
        assert_null(self);
        if (!strstr(err.msg, bad[k][1])) fail_msg("%s: expected '%s' in: %s", bad[k][0], bad[k][1], err.msg);
    }
}

/* fit, save, load into a fresh instance: the same transfer bit for bit
 * (same pair stream), for both read-outs; the transfer lands near frame j
 * (inside its bounding box grown by the output range). */
static void test_fit_save_load_transfer(void **state)
{
    const char *dir = *state;
    const tcb_method_ops *ops = tcb_registry_find("cc");
    tcb_sequence s = make_seq();
    static const char *const params[] = {"{\"preset\": \"tiny\", \"iterations\": 6, \"points\": 100}",
                                         "{\"preset\": \"tiny\", \"iterations\": 6, \"readout\": \"vertices\"}"};
    for (int k = 0; k < 2; k++) {
        void *a = create_ok(params[k]), *b = create_ok(params[k]);
        tcb_error err = {0};
        tcb_fit_ctx ctx = {.seed = SEED, .n_threads = 1, .work_dir = dir};
        assert_int_equal(ops->fit(a, &s, &ctx, &err), TCB_OK);
        char path[TCB_PATH_MAX];
        assert_int_equal(tcb_path_join(path, sizeof path, &err, "%s/model.ckpt", dir), TCB_OK);
        assert_int_equal(ops->save(a, path, &err), TCB_OK);
        assert_int_equal(ops->load(b, &s, path, &err), TCB_OK);
        size_t n = (size_t)s.n_verts;
        float *oa = malloc(n * 3 * sizeof(float)), *ob = malloc(n * 3 * sizeof(float));
        tcb_rng ra, rb;
        tcb_rng_seed(&ra, 7), tcb_rng_seed(&rb, 7);
        assert_int_equal(ops->transfer(a, &s, 1, 4, tcb_seq_frame(&s, 1), (int)n, oa, &ra, &err), TCB_OK);
        assert_int_equal(ops->transfer(b, &s, 1, 4, tcb_seq_frame(&s, 1), (int)n, ob, &rb, &err), TCB_OK);
        assert_memory_equal(oa, ob, n * 3 * sizeof(float));
        for (size_t i = 0; i < n * 3; i++) assert_true(isfinite(oa[i]) && fabsf(oa[i]) < 10);
        assert_int_equal(ops->transfer(a, &s, 1, 99, tcb_seq_frame(&s, 1), (int)n, oa, &ra, &err), TCB_ERR_INPUT);
        free(oa), free(ob);
        ops->destroy(a), ops->destroy(b);
        remove(path);
    }
    /* a model file of other dimensions is refused with the key */
    void *big = create_ok("{\"preset\": \"tiny\", \"latent\": 10}"), *a = create_ok("{\"preset\": \"tiny\", \"iterations\": 2}");
    tcb_error err = {0};
    tcb_fit_ctx ctx = {.seed = SEED, .n_threads = 1};
    assert_int_equal(ops->fit(a, &s, &ctx, &err), TCB_OK);
    char path[TCB_PATH_MAX];
    assert_int_equal(tcb_path_join(path, sizeof path, &err, "%s/model.ckpt", dir), TCB_OK);
    assert_int_equal(ops->save(a, path, &err), TCB_OK);
    assert_int_equal(ops->load(big, &s, path, &err), TCB_ERR_INPUT);
    assert_non_null(strstr(err.msg, "Z"));
    ops->destroy(a), ops->destroy(big);
    tcb_sequence_free(&s);
}

int main(void)
{
    /* one thread: these sizes are far below what a thread team pays for */
    omp_set_num_threads(1);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_loss_decreases),
        cmocka_unit_test(test_warmup),
        cmocka_unit_test(test_adam_recreated_at_decays),
        cmocka_unit_test_setup_teardown(test_resume_bit_identical, tu_setup_tmpdir, tu_teardown_tmpdir),
        cmocka_unit_test_setup_teardown(test_damaged_and_foreign_refused, tu_setup_tmpdir, tu_teardown_tmpdir),
        cmocka_unit_test(test_divergence_stops),
        cmocka_unit_test(test_params_refused),
        cmocka_unit_test_setup_teardown(test_fit_save_load_transfer, tu_setup_tmpdir, tu_teardown_tmpdir),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
