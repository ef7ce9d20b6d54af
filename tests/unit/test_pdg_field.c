/* methods/pdg/field.c: the per-transition translation field against a
 * double reference written here (y = x + 0.1 tanh(mean_l S_l(V_l, x)),
 * S_l the trilinear sample of tu_ref_trilinear), its gradients in the
 * values and in the points by central differences of ℓ = Σ a·y, the
 * parameter layout (level-major, one-node level 0), and the solve as the
 * inverse of the Sobolev apply on every level and transition. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>

#include "methods/pdg/field.h"
#include "tcb/rng.h"
#include "testutil.h"

enum { LEVELS = 4, T = 3, N = 30 };
#define FD_H 1e-6

/* y of one point through field g, in double. */
static void ref_move(const tcb_pdg_fields *f, const double *V, int g, const double x[3], double y[3])
{
    double s[3] = {0, 0, 0}, o[3];
    for (int l = 0; l < f->levels; l++) {
        const double *v = V + f->off[l] + (size_t)g * f->r[l] * f->r[l] * f->r[l] * 3;
        tu_ref_trilinear(v, f->r[l], 3, x, o);
        for (int a = 0; a < 3; a++) s[a] += o[a] / f->levels;
    }
    for (int a = 0; a < 3; a++) y[a] = x[a] + 0.1 * tanh(s[a]);
}

static double ref_objective(const tcb_pdg_fields *f, const double *V, int g, const double *x, const float *a)
{
    double l = 0.0, y[3];
    for (int p = 0; p < N; p++) {
        ref_move(f, V, g, x + 3 * p, y);
        for (int k = 0; k < 3; k++) l += a[3 * p + k] * y[k];
    }
    return l;
}

static tcb_pdg_fields make(void)
{
    tcb_pdg_fields f;
    tcb_error err = {0};
    assert_int_equal(tcb_pdg_fields_init(&f, LEVELS, T, 0.25, 1.5, &err), TCB_OK);
    return f;
}

/* Points inside cells (off the walls where the sample has kinks). */
static void random_points(tcb_rng *rng, const tcb_pdg_fields *f, float *x)
{
    int r = f->r[f->levels - 1];
    for (int i = 0; i < 3 * N; i++) {
        int c = (int)(tcb_rng_uniform(rng) * (r - 1));
        x[i] = (float)(-1.0 + 2.0 * (c + 0.1 + 0.8 * tcb_rng_uniform(rng)) / (r - 1));
    }
}

static void test_layout(void **state)
{
    (void)state;
    tcb_pdg_fields f = make();
    const int r[LEVELS] = {1, 3, 5, 7};
    size_t total = 0;
    for (int l = 0; l < LEVELS; l++) {
        assert_int_equal(f.r[l], r[l]);
        assert_int_equal(f.off[l], total);
        total += (size_t)T * r[l] * r[l] * r[l] * 3;
    }
    assert_int_equal(f.off[LEVELS], total);
    tcb_pdg_fields_free(&f);
    tcb_error err = {0};
    assert_int_equal(tcb_pdg_fields_init(&f, 0, T, 0.25, 1.5, &err), TCB_ERR_INPUT);
    assert_int_equal(tcb_pdg_fields_init(&f, 3, 0, 0.25, 1.5, &err), TCB_ERR_INPUT);
}

static void test_forward_and_gradients(void **state)
{
    (void)state;
    tcb_pdg_fields f = make();
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 1, "pdg-field");
    size_t nv = f.off[LEVELS];
    float *V = tu_falloc(nv), *dV = tu_falloc(nv), x[3 * N], y[3 * N], s[3 * N], a[3 * N], dx[3 * N] = {0},
          ds[3 * N];
    tu_fill_uniform(&rng, V, nv, -2.0, 2.0);
    random_points(&rng, &f, x);
    tu_fill_uniform(&rng, a, 3 * N, -1.0, 1.0);
    const int g = 1;
    tcb_pdg_field_forward(&f, V, g, x, N, s, y);
    double *Vd = tu_to_double(V, nv), *xd = tu_to_double(x, 3 * N), want[3];
    for (int p = 0; p < N; p++) {
        ref_move(&f, Vd, g, xd + 3 * p, want);
        for (int k = 0; k < 3; k++) assert_near(y[3 * p + k], want[k], 1e-6);
    }
    tcb_pdg_field_backward(&f, V, g, x, N, s, a, dV, dx, ds);
    /* values: every entry of field g's levels, and none of the other fields */
    for (size_t e = 0; e < nv; e++) {
        double keep = Vd[e];
        Vd[e] = keep + FD_H;
        double lp = ref_objective(&f, Vd, g, xd, a);
        Vd[e] = keep - FD_H;
        double lm = ref_objective(&f, Vd, g, xd, a);
        Vd[e] = keep;
        assert_near(dV[e], (lp - lm) / (2 * FD_H), 1e-5);
    }
    for (int i = 0; i < 3 * N; i++) {
        double keep = xd[i];
        xd[i] = keep + FD_H;
        double lp = ref_objective(&f, Vd, g, xd, a);
        xd[i] = keep - FD_H;
        double lm = ref_objective(&f, Vd, g, xd, a);
        xd[i] = keep;
        assert_near(dx[i], (lp - lm) / (2 * FD_H), 1e-4);
    }
    free(V), free(dV), free(Vd), free(xd);
    tcb_pdg_fields_free(&f);
}

/* V = M⁻¹ U per level and transition: applying M to V gives U back. */
static void test_solve(void **state)
{
    (void)state;
    tcb_pdg_fields f = make();
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 2, "pdg-field");
    size_t nv = f.off[LEVELS];
    float *U = tu_falloc(nv), *V = tu_falloc(nv), *back = tu_falloc(nv);
    double *scratch = tu_dalloc(tcb_pdg_fields_scratch(&f));
    tu_fill_uniform(&rng, U, nv, -1.0, 1.0);
    tcb_pdg_fields_solve(&f, U, V, scratch);
    for (int l = 0; l < LEVELS; l++)
        for (int g = 0; g < T; g++) {
            size_t at = tcb_pdg_level(&f, V, g, l) - V;
            tcb_sobolev_apply(&f.sobolev[l], 3, V + at, back + at);
        }
    for (size_t i = 0; i < nv; i++) assert_near(back[i], U[i], 1e-5);
    /* level 0, one node: M = I */
    for (size_t i = 0; i < f.off[1]; i++) assert_true(V[i] == U[i]);
    free(U), free(V), free(back), free(scratch);
    tcb_pdg_fields_free(&f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_layout), cmocka_unit_test(test_forward_and_gradients),
                                       cmocka_unit_test(test_solve)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
