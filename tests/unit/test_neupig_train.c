/* methods/neupig/train.c on a small problem (an icosahedron turning and
 * moving over five frames, its vertices the frames' points): the loss falls, a training checkpointed and
 * continued is bit-identical to one run straight through, and a
 * checkpoint of other settings is refused. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "methods/neupig/train.h"
#include "testutil.h"

enum { NV = 12, NF = 20, NE = 30, T = 5, NP = NV };

typedef struct fixture {
    float verts[NV * 3], normals[NV * 3], edge_len[NE], pts[T][NP * 3];
    int32_t edges[NE * 2];
    const float *points[T];
    int n_points[T];
    tcb_nn *index[T];
    tcb_neupig_problem problem;
} fixture;

static const int32_t faces[NF * 3] = {0, 11, 5, 0, 5, 1, 0, 1, 7, 0, 7, 10, 0, 10, 11, 1, 5, 9, 5, 11, 4,
                                      11, 10, 2, 10, 7, 6, 7, 1, 8, 3, 9, 4, 3, 4, 2, 3, 2, 6, 3, 6, 8,
                                      3, 8, 9, 4, 9, 5, 2, 4, 11, 6, 2, 10, 8, 6, 7, 9, 8, 1};

static void build(fixture *f)
{
    const double p = (1.0 + sqrt(5.0)) / 2.0;
    const double v[NV][3] = {{-1, p, 0}, {1, p, 0}, {-1, -p, 0}, {1, -p, 0}, {0, -1, p}, {0, 1, p},
                             {0, -1, -p}, {0, 1, -p}, {p, 0, -1}, {p, 0, 1}, {-p, 0, -1}, {-p, 0, 1}};
    double len = sqrt(1.0 + p * p);
    for (int i = 0; i < NV; i++)
        for (int k = 0; k < 3; k++) f->normals[3 * i + k] = (float)(v[i][k] / len), f->verts[3 * i + k] = 0.5f * f->normals[3 * i + k];
    int ne = 0;
    for (int t = 0; t < NF; t++)
        for (int s = 0; s < 3; s++) {
            int a = faces[3 * t + s], b = faces[3 * t + (s + 1) % 3];
            if (a > b) continue; /* each edge once: from its lower end */
            f->edges[2 * ne] = a, f->edges[2 * ne + 1] = b;
            f->edge_len[ne++] = 0.5f * 2.0f / (float)len;
        }
    assert_int_equal(ne, NE);
    tcb_error err = {0};
    for (int t = 0; t < T; t++) {
        double c = cos(0.15 * t), s = sin(0.15 * t);
        float moved[NV * 3];
        for (int i = 0; i < NV; i++) {
            const float *x = f->verts + 3 * i;
            moved[3 * i] = (float)(c * x[0] + s * x[2] + 0.05 * t);
            moved[3 * i + 1] = x[1];
            moved[3 * i + 2] = (float)(-s * x[0] + c * x[2]);
        }
        memcpy(f->pts[t], moved, sizeof moved);
        f->points[t] = f->pts[t], f->n_points[t] = NP;
        assert_int_equal(tcb_nn_build(f->pts[t], NP, &f->index[t], &err), TCB_OK);
    }
    f->problem = (tcb_neupig_problem){NV, f->verts, f->normals, NE, f->edges, f->edge_len, T, f->points,
                                      f->n_points, (const tcb_nn *const *)f->index, 2};
}

static void release(fixture *f)
{
    for (int t = 0; t < T; t++) tcb_nn_free(f->index[t]);
}

static tcb_neupig_arch small_arch(void)
{
    tcb_neupig_arch a = tcb_neupig_arch_reference();
    a.levels = 3, a.features = 8, a.normal_res = 3, a.time_freqs = 2, a.hidden = 32;
    return a;
}

static const tcb_neupig_schedule sched = {200, 0.005, 2.5, 1e-3, 0.0};

static void start(tcb_neupig_trainer *t, const tcb_neupig_arch *a, const fixture *f)
{
    tcb_error err = {0};
    assert_int_equal(tcb_neupig_trainer_init(t, a, &sched, &f->problem, 7, &err), TCB_OK);
}

static void steps(tcb_neupig_trainer *t, int n, double *loss)
{
    tcb_error err = {0};
    for (int i = 0; i < n; i++)
        if (tcb_neupig_train_step(t, loss, &err)) fail_msg("%s", err.msg);
}

/* The fixture built and a trainer of the small architecture started on it. */
static void begin(fixture *f, tcb_neupig_trainer *t)
{
    build(f);
    tcb_neupig_arch a = small_arch();
    start(t, &a, f);
}

static void test_loss_falls(void **state)
{
    (void)state;
    fixture f;
    tcb_neupig_trainer t;
    begin(&f, &t);
    double first, last;
    steps(&t, 1, &first);
    steps(&t, 199, &last);
    printf("loss: epoch 0 %.6g, epoch 199 %.6g (chamfer %.6g, edge %.6g)\n", first, last, t.last.chamfer,
           t.last.edge);
    assert_true(last < 0.5 * first);
    tcb_neupig_trainer_free(&t);
    release(&f);
}

/* An epoch's buffers are reused: two evaluations through one work equal
 * one through a fresh work (nothing accumulates across calls), and a work
 * made for other sizes is refused, not overrun. */
static void test_work_reused_and_checked(void **state)
{
    (void)state;
    fixture f;
    tcb_neupig_trainer t;
    begin(&f, &t);
    steps(&t, 3, &(double){0}); /* parameters away from the start */
    size_t n = t.model.n_params;
    float *g1 = malloc(n * sizeof *g1), *g2 = malloc(n * sizeof *g2);
    tcb_error err = {0};
    tcb_neupig_loss l1, l2;
    tcb_neupig_work fresh;
    assert_int_equal(tcb_neupig_work_init(&fresh, &t.model, &f.problem, &err), TCB_OK);
    assert_int_equal(tcb_neupig_loss_grad(&t.model, t.params, &f.problem, &t.work, 3, 200, &l1, g1, &err), TCB_OK);
    assert_int_equal(tcb_neupig_loss_grad(&t.model, t.params, &f.problem, &t.work, 3, 200, &l1, g1, &err), TCB_OK);
    assert_int_equal(tcb_neupig_loss_grad(&t.model, t.params, &f.problem, &fresh, 3, 200, &l2, g2, &err), TCB_OK);
    assert_true(l1.total == l2.total && l1.chamfer == l2.chamfer && l1.edge == l2.edge);
    assert_memory_equal(g1, g2, n * sizeof *g1);
    assert_memory_equal(t.work.cd, fresh.cd, (size_t)T * sizeof *fresh.cd);
    tcb_neupig_problem fewer = f.problem;
    fewer.T = T - 1;
    assert_int_equal(tcb_neupig_loss_grad(&t.model, t.params, &fewer, &fresh, 3, 200, &l2, g2, &err),
                     TCB_ERR_INTERNAL);
    assert_non_null(strstr(err.msg, "work for"));
    tcb_neupig_work_free(&fresh);
    free(g1), free(g2);
    tcb_neupig_trainer_free(&t);
    release(&f);
}

static void test_resume_bit_identical(void **state)
{
    const char *dir = *state;
    fixture f;
    build(&f);
    tcb_neupig_arch a = small_arch();
    tcb_neupig_trainer straight, first, second;
    double loss;
    start(&straight, &a, &f);
    steps(&straight, 8, &loss);
    start(&first, &a, &f);
    steps(&first, 4, &loss);
    char path[4096];
    snprintf(path, sizeof path, "%s/train.ckpt", dir);
    tcb_error err = {0};
    assert_int_equal(tcb_neupig_train_save(&first, 7, 1.5, path, &err), TCB_OK);
    tcb_neupig_trainer_free(&first);
    start(&second, &a, &f);
    double seconds;
    assert_int_equal(tcb_neupig_train_load(&second, 7, path, &seconds, &err), TCB_OK);
    assert_true(second.it == 4 && seconds == 1.5);
    steps(&second, 4, &loss);
    assert_memory_equal(second.params, straight.params, straight.model.n_params * sizeof(float));
    tcb_neupig_trainer_free(&second);
    /* Another architecture refuses the file, naming what differs. */
    a.hidden = 16;
    start(&second, &a, &f);
    assert_int_equal(tcb_neupig_train_load(&second, 7, path, &seconds, &err), TCB_ERR_INPUT);
    assert_non_null(strstr(err.msg, "hidden"));
    tcb_neupig_trainer_free(&second);
    tcb_neupig_trainer_free(&straight);
    release(&f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_loss_falls),
        cmocka_unit_test(test_work_reused_and_checked),
        cmocka_unit_test_setup_teardown(test_resume_bit_identical, tu_setup_tmpdir, tu_teardown_tmpdir)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
