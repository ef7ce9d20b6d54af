/* methods/pdg/train.c on a small problem (an icosahedron turning and
 * moving over five frames, its vertices the frames' points, the template
 * the keyframe's icosahedron): the loss falls through and after the
 * warm-up, with either rotation, and the cayley rotation fits the turning
 * shape better than translations alone; a training checkpointed and continued
 * (across the warm-up's end) is bit-identical to one run straight
 * through, a checkpoint of other settings (another rotation among them)
 * is refused, and the template's gradient in its Large-Steps parameters u
 * is the central difference of RC(M⁻¹u, keyframe points), with M built
 * densely here. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "methods/pdg/train.h"
#include "testutil.h"

enum { NV = 12, NF = 20, T = 5, KEY = 2 };

static const int32_t faces[NF * 3] = {0, 11, 5, 0, 5, 1, 0, 1, 7, 0, 7, 10, 0, 10, 11, 1, 5, 9, 5, 11, 4,
                                      11, 10, 2, 10, 7, 6, 7, 1, 8, 3, 9, 4, 3, 4, 2, 3, 2, 6, 3, 6, 8,
                                      3, 8, 9, 4, 9, 5, 2, 4, 11, 6, 2, 10, 8, 6, 7, 9, 8, 1};

typedef struct fixture {
    float verts[NV * 3], pts[T][NV * 3];
    const float *points[T];
    int n_points[T];
    tcb_nn *index[T];
    tcb_mesh template_mesh;
    tcb_pdg_data data;
} fixture;

static void build(fixture *f)
{
    const double p = (1.0 + sqrt(5.0)) / 2.0, len = sqrt(1.0 + p * p);
    const double v[NV][3] = {{-1, p, 0}, {1, p, 0}, {-1, -p, 0}, {1, -p, 0}, {0, -1, p}, {0, 1, p},
                             {0, -1, -p}, {0, 1, -p}, {p, 0, -1}, {p, 0, 1}, {-p, 0, -1}, {-p, 0, 1}};
    tcb_error err = {0};
    for (int t = 0; t < T; t++) {
        double c = cos(0.15 * (t - KEY)), s = sin(0.15 * (t - KEY));
        for (int i = 0; i < NV; i++) {
            double x[3] = {0.5 * v[i][0] / len, 0.5 * v[i][1] / len, 0.5 * v[i][2] / len};
            f->pts[t][3 * i] = (float)(c * x[0] + s * x[2] + 0.05 * (t - KEY));
            f->pts[t][3 * i + 1] = (float)x[1];
            f->pts[t][3 * i + 2] = (float)(-s * x[0] + c * x[2]);
        }
        f->points[t] = f->pts[t], f->n_points[t] = NV;
        assert_int_equal(tcb_nn_build(f->pts[t], NV, &f->index[t], &err), TCB_OK);
    }
    /* the template: the keyframe's shape, a little off it (so its Chamfer pulls) */
    for (int i = 0; i < 3 * NV; i++) f->verts[i] = 1.05f * f->pts[KEY][i];
    f->template_mesh = (tcb_mesh){NV, NF, f->verts, (int32_t *)faces};
    f->data = (tcb_pdg_data){T, KEY, f->points, f->n_points, (const tcb_nn *const *)f->index, &f->template_mesh};
}

static void release(fixture *f)
{
    for (int t = 0; t < T; t++) tcb_nn_free(f->index[t]);
}

static tcb_pdg_arch small_arch(tcb_pdg_rotation rotation)
{
    tcb_pdg_arch a = tcb_pdg_arch_reference();
    a.levels = 4, a.rotation = rotation;
    return a;
}

static const tcb_pdg_schedule sched = {200, 20, 0.005, 1.1, 1e-4, 0.0};

static void start(tcb_pdg_trainer *t, const tcb_pdg_arch *a, const fixture *f)
{
    tcb_error err = {0};
    if (tcb_pdg_trainer_init(t, a, &sched, &f->data, &err)) fail_msg("%s", err.msg);
}

static void steps(tcb_pdg_trainer *t, int n, double *loss)
{
    tcb_error err = {0};
    for (int i = 0; i < n; i++)
        if (tcb_pdg_train_step(t, loss, &err)) fail_msg("%s", err.msg);
}

/* The fixture and a trainer of the small architecture on it. */
static void begin(fixture *f, tcb_pdg_trainer *t, tcb_pdg_rotation rotation)
{
    build(f);
    tcb_pdg_arch a = small_arch(rotation);
    start(t, &a, f);
}

/* The loss after 200 epochs, having checked that it falls in and after
 * the warm-up (by `factor` after it). */
static double loss_falls(tcb_pdg_rotation rotation, double factor)
{
    fixture f;
    tcb_pdg_trainer t;
    begin(&f, &t, rotation);
    double first, warm, after, last;
    steps(&t, 1, &first);
    steps(&t, 19, &warm);
    steps(&t, 1, &after);
    steps(&t, 179, &last);
    printf("%s loss: epoch 0 %.6g, 19 %.6g (input only); 20 %.6g, 199 %.6g (input %.4g, pred %.4g, edge %.4g), "
           "template %.4g\n", tcb_pdg_rotation_names[rotation], first, warm, after, last, t.last.input, t.last.pred,
           t.last.edge, t.template_loss);
    assert_true(warm < first);
    assert_true(last < factor * after);
    tcb_pdg_trainer_free(&t);
    release(&f);
    return last;
}

static void test_loss_falls(void **state)
{
    (void)state;
    double released = loss_falls(TCB_PDG_RELEASED, 0.7); /* measured 0.611 -> 0.357 */
    double cayley = loss_falls(TCB_PDG_CAYLEY, 0.2);     /* measured 1.64 -> 0.0783 */
    assert_true(cayley < 0.5 * released); /* the shape turns: the rotation fits it, translations alone less so */
}

static void test_resume_bit_identical(void **state)
{
    const char *dir = *state;
    fixture f;
    build(&f);
    tcb_pdg_arch a = small_arch(TCB_PDG_RELEASED);
    tcb_pdg_trainer straight, first, second;
    double loss;
    start(&straight, &a, &f);
    steps(&straight, 30, &loss);
    start(&first, &a, &f);
    steps(&first, 15, &loss);
    char path[4096];
    snprintf(path, sizeof path, "%s/train.ckpt", dir);
    tcb_error err = {0};
    assert_int_equal(tcb_pdg_train_save(&first, 7, 1.5, path, &err), TCB_OK);
    tcb_pdg_trainer_free(&first);
    start(&second, &a, &f);
    double seconds;
    assert_int_equal(tcb_pdg_train_load(&second, 7, path, &seconds, &err), TCB_OK);
    assert_true(second.it == 15 && seconds == 1.5);
    steps(&second, 15, &loss);
    assert_memory_equal(second.params, straight.params, straight.n_params * sizeof(float));
    tcb_pdg_trainer_free(&second);
    a.levels = 3; /* another architecture: refused, naming what differs */
    start(&second, &a, &f);
    assert_int_equal(tcb_pdg_train_load(&second, 7, path, &seconds, &err), TCB_ERR_INPUT);
    assert_non_null(strstr(err.msg, "levels"));
    tcb_pdg_trainer_free(&second);
    a = small_arch(TCB_PDG_CAYLEY); /* the other rotation: refused, naming it */
    start(&second, &a, &f);
    assert_int_equal(tcb_pdg_train_load(&second, 7, path, &seconds, &err), TCB_ERR_INPUT);
    assert_non_null(strstr(err.msg, "rotation"));
    tcb_pdg_trainer_free(&second);
    tcb_pdg_trainer_free(&straight);
    release(&f);
}

/* x = M⁻¹ b, M dense [NV][NV], by Gaussian elimination (M is SPD). */
static void dense_solve(const double *M, const double *b, double *x)
{
    double a[NV][NV + 3];
    for (int i = 0; i < NV; i++) {
        for (int j = 0; j < NV; j++) a[i][j] = M[i * NV + j];
        for (int k = 0; k < 3; k++) a[i][NV + k] = b[3 * i + k];
    }
    for (int c = 0; c < NV; c++)
        for (int r = c + 1; r < NV; r++) {
            double f = a[r][c] / a[c][c];
            for (int j = c; j < NV + 3; j++) a[r][j] -= f * a[c][j];
        }
    for (int i = NV - 1; i >= 0; i--)
        for (int k = 0; k < 3; k++) {
            double s = a[i][NV + k];
            for (int j = i + 1; j < NV; j++) s -= a[i][j] * x[3 * j + k];
            x[3 * i + k] = s / a[i][i];
        }
}

static double template_objective(const double *M, const double *u, const double *P, const double *wv,
                                  const double *wp)
{
    double v[3 * NV];
    dense_solve(M, u, v);
    return tu_ref_chamfer_way(v, NV, P, NV, wv, NULL) + tu_ref_chamfer_way(P, NV, v, NV, wp, NULL);
}

static void test_template_gradient(void **state)
{
    (void)state;
    fixture f;
    tcb_pdg_trainer t;
    begin(&f, &t, TCB_PDG_RELEASED);
    const tcb_pdg_arch a = t.arch;
    double loss;
    steps(&t, 1, &loss); /* the step leaves its gradient in grads: du at the start's u */
    size_t nf = t.fields.off[t.fields.levels];
    double M[NV * NV] = {0}, u[3 * NV], P[3 * NV], v0[3 * NV], wv[NV], wp[NV];
    for (int i = 0; i < NV; i++) M[i * NV + i] = 1.0;
    for (int k = 0; k < NF; k++)
        for (int s = 0; s < 3; s++) {
            int i = faces[3 * k + s], j = faces[3 * k + (s + 1) % 3]; /* each edge twice, once each way */
            M[i * NV + j] = -a.template_lambda;
            M[i * NV + i] += 0.5 * a.template_lambda;
            M[j * NV + j] += 0.5 * a.template_lambda;
        }
    for (int i = 0; i < 3 * NV; i++) u[i] = 0, P[i] = f.pts[KEY][i];
    for (int i = 0; i < NV; i++)
        for (int j = 0; j < NV; j++)
            for (int k = 0; k < 3; k++) u[3 * i + k] += M[i * NV + j] * f.verts[3 * j + k];
    dense_solve(M, u, v0);
    tu_ref_chamfer_way(v0, NV, P, NV, NULL, wv);
    tu_ref_chamfer_way(P, NV, v0, NV, NULL, wp);
    assert_near(t.template_loss, template_objective(M, u, P, wv, wp), 1e-5);
    for (int i = 0; i < 3 * NV; i++) {
        double keep = u[i], h = 1e-6;
        u[i] = keep + h;
        double lp = template_objective(M, u, P, wv, wp);
        u[i] = keep - h;
        double lm = template_objective(M, u, P, wv, wp);
        u[i] = keep;
        assert_near(t.grads[nf + i], (lp - lm) / (2 * h), 1e-4 * fabs((lp - lm) / (2 * h)) + 1e-6);
    }
    tcb_pdg_trainer_free(&t);
    release(&f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_loss_falls),
        cmocka_unit_test_setup_teardown(test_resume_bit_identical, tu_setup_tmpdir, tu_teardown_tmpdir),
        cmocka_unit_test(test_template_gradient)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
