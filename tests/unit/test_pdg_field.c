/* methods/pdg/field.c: the per-transition field against a double
 * reference (tu_ref_pdg_step: the level mean of tu_ref_trilinear samples,
 * the step [R | 0.1 tanh(s_t)] composed as the release composes it, R the
 * Cayley rotation solved as (I − K)⁻¹(I + K)), its gradients in the
 * values, the points and the carried transform by central differences of
 * ℓ = Σ a·y + Σ b·A', for the released translation and the cayley
 * rotation, with and without a carry; the Cayley map itself (a rotation,
 * its definition, its gradient and its application's in r and x); the
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

/* The points in double: where the field samples, and with a carry the
 * chain's start and its transform so far. */
typedef struct pts {
    double *x, *x0, *A; /* [N][3], [N][3], [N][12]; A NULL: no carry */
} pts;

/* What ℓ = Σ a·y + Σ b·A' reads (b NULL: no A' term). */
typedef struct field_case {
    const tcb_pdg_fields *f;
    const double *V;
    int g;
    pts p;
    const float *a, *b;
} field_case;

static double ref_objective(const void *ctx)
{
    const field_case *c = ctx;
    double l = 0.0, y[3], A[12];
    for (int i = 0; i < N; i++) {
        const double *x = c->p.x + 3 * i;
        tu_ref_pdg_step(c->f, c->V, c->g, x, c->p.A ? c->p.x0 + 3 * i : x, c->p.A ? c->p.A + 12 * i : NULL, A, y);
        for (int k = 0; k < 3; k++) l += c->a[3 * i + k] * y[k];
        for (int k = 0; c->b && k < 12; k++) l += c->b[12 * i + k] * A[k];
    }
    return l;
}

static tcb_pdg_fields make(tcb_pdg_rotation rotation)
{
    tcb_pdg_fields f;
    tcb_error err = {0};
    assert_int_equal(tcb_pdg_fields_init(&f, LEVELS, T, rotation, 0.25, 1.5, &err), TCB_OK);
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
    for (int rot = TCB_PDG_RELEASED; rot <= TCB_PDG_CAYLEY; rot++) {
        tcb_pdg_fields f = make((tcb_pdg_rotation)rot);
        const int r[LEVELS] = {1, 3, 5, 7}, C = rot == TCB_PDG_CAYLEY ? 6 : 3;
        assert_int_equal(f.C, C);
        size_t total = 0;
        for (int l = 0; l < LEVELS; l++) {
            assert_int_equal(f.r[l], r[l]);
            assert_int_equal(f.off[l], total);
            total += (size_t)T * r[l] * r[l] * r[l] * C;
        }
        assert_int_equal(f.off[LEVELS], total);
        tcb_pdg_fields_free(&f);
    }
    tcb_pdg_fields f;
    tcb_error err = {0};
    assert_int_equal(tcb_pdg_fields_init(&f, 0, T, TCB_PDG_RELEASED, 0.25, 1.5, &err), TCB_ERR_INPUT);
    assert_int_equal(tcb_pdg_fields_init(&f, 3, 0, TCB_PDG_RELEASED, 0.25, 1.5, &err), TCB_ERR_INPUT);
    assert_int_equal(tcb_pdg_fields_init(&f, 3, T, (tcb_pdg_rotation)2, 0.25, 1.5, &err), TCB_ERR_INPUT);
}

/* The field's forward against the reference and every gradient against
 * central differences: the values (every entry of field g's levels, and
 * none of the other fields), the points (where the field samples; without
 * a carry also where y starts) and, with a carry, the transform so far. */
static void check_field(tcb_pdg_rotation rotation, int carry, uint64_t seed)
{
    tcb_pdg_fields f = make(rotation);
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, seed, "pdg-field");
    size_t nv = f.off[LEVELS];
    float *V = tu_falloc(nv), *dV = tu_falloc(nv), x[3 * N], y[3 * N], s[6 * N], a[3 * N], dx[3 * N] = {0},
          ds[6 * N], x0[3 * N], A[12 * N], A_out[12 * N], b[12 * N], dA[12 * N] = {0};
    tu_fill_uniform(&rng, V, nv, -2.0, 2.0);
    random_points(&rng, &f, x);
    tu_fill_uniform(&rng, a, 3 * N, -1.0, 1.0);
    tu_fill_uniform(&rng, x0, 3 * N, -1.0, 1.0);
    tu_fill_uniform(&rng, A, 12 * N, -1.0, 1.0);
    tu_fill_uniform(&rng, b, 12 * N, -1.0, 1.0);
    const tcb_pdg_carry c = {x0, A, A_out, b, dA}, *cp = carry ? &c : NULL;
    const int g = 1;
    tcb_pdg_field_forward(&f, V, g, x, N, cp, s, y);
    double *Vd = tu_to_double(V, nv), want[3], want_A[12];
    const pts p = {tu_to_double(x, 3 * N), tu_to_double(x0, 3 * N), carry ? tu_to_double(A, 12 * N) : NULL};
    const field_case fc = {&f, Vd, g, p, a, carry ? b : NULL};
    for (int i = 0; i < N; i++) {
        const double *xi = p.x + 3 * i;
        tu_ref_pdg_step(&f, Vd, g, xi, carry ? p.x0 + 3 * i : xi, carry ? p.A + 12 * i : NULL, want_A, want);
        for (int k = 0; k < 3; k++) assert_near(y[3 * i + k], want[k], 1e-6);
        for (int k = 0; carry && k < 12; k++) assert_near(A_out[12 * i + k], want_A[k], 1e-6);
    }
    tcb_pdg_field_backward(&f, V, g, x, N, cp, s, a, dV, dx, ds);
    double worst = 0.0;
    for (size_t e = 0; e < nv; e++) {
        double fd = tu_central(ref_objective, &fc, Vd + e, FD_H);
        worst = fmax(worst, fabs(dV[e] - fd) / (fabs(fd) + 1e-3));
        assert_near(dV[e], fd, 1e-5 + 1e-5 * fabs(fd));
    }
    for (int i = 0; i < 3 * N; i++) {
        double fd = tu_central(ref_objective, &fc, p.x + i, FD_H);
        worst = fmax(worst, fabs(dx[i] - fd) / (fabs(fd) + 1e-3));
        assert_near(dx[i], fd, 1e-4 + 1e-5 * fabs(fd));
    }
    for (int i = 0; carry && i < 12 * N; i++) {
        double fd = tu_central(ref_objective, &fc, p.A + i, FD_H);
        worst = fmax(worst, fabs(dA[i] - fd) / (fabs(fd) + 1e-3));
        assert_near(dA[i], fd, 1e-5 + 1e-5 * fabs(fd));
    }
    print_message("%s%s: worst relative gradient error %.2e\n", tcb_pdg_rotation_names[rotation],
                  carry ? ", carried" : "", worst);
    free(V), free(dV), free(Vd), free(p.x), free(p.x0), free(p.A);
    tcb_pdg_fields_free(&f);
}

typedef struct kase {
    tcb_pdg_rotation rotation;
    int carry;
    uint64_t seed;
} kase;

static void test_field(void **state)
{
    const kase *k = *state;
    check_field(k->rotation, k->carry, k->seed);
}

/* What ℓ(r, x) = ⟨G, R(r)⟩ + a·R(r)x reads. */
typedef struct cayley_case {
    double r[3], G[9], x[3], a[3];
} cayley_case;

static double ref_cayley_objective(const void *ctx)
{
    const cayley_case *c = ctx;
    double R[9], l = 0.0;
    tu_ref_cayley(c->r, R);
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) l += (c->G[3 * i + j] + c->a[i] * c->x[j]) * R[3 * i + j];
    return l;
}

/* The closed form against the definition: a rotation, the reference's R
 * (I − K)⁻¹(I + K); its gradient, and that of its application R x, in r
 * and x by central differences, at small and large angles. */
static void test_cayley_map(void **state)
{
    (void)state;
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 5, "pdg-cayley");
    double worst = 0.0;
    for (int trial = 0; trial < 40; trial++) {
        float r[3], G[9], R[9], dR[9], dr[3], x[3], a[3];
        double scale = trial < 20 ? 0.3 : 3.0;
        tu_fill_uniform(&rng, r, 3, -scale, scale);
        tu_fill_uniform(&rng, G, 9, -1.0, 1.0);
        tu_fill_uniform(&rng, x, 3, -1.0, 1.0);
        tu_fill_uniform(&rng, a, 3, -1.0, 1.0);
        tcb_pdg_cayley_forward(r, R);
        cayley_case c;
        double Rd[9];
        for (int k = 0; k < 3; k++) c.r[k] = r[k], c.x[k] = x[k], c.a[k] = a[k];
        for (int k = 0; k < 9; k++) c.G[k] = G[k];
        tu_ref_cayley(c.r, Rd);
        for (int k = 0; k < 9; k++) assert_near(R[k], Rd[k], 1e-6);
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++) {
                double RtR = 0.0;
                for (int k = 0; k < 3; k++) RtR += Rd[3 * k + i] * Rd[3 * k + j];
                assert_near(RtR, i == j, 1e-12);
            }
        double det = Rd[0] * (Rd[4] * Rd[8] - Rd[5] * Rd[7]) - Rd[1] * (Rd[3] * Rd[8] - Rd[5] * Rd[6]) +
                     Rd[2] * (Rd[3] * Rd[7] - Rd[4] * Rd[6]);
        assert_near(det, 1.0, 1e-12);
        /* ∂ℓ/∂R = G + a xᵀ; ∂ℓ/∂x = Rᵀ a */
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++) dR[3 * i + j] = G[3 * i + j] + a[i] * x[j];
        tcb_pdg_cayley_backward(r, dR, dr);
        for (int k = 0; k < 3; k++) {
            double fd = tu_central(ref_cayley_objective, &c, c.r + k, FD_H);
            worst = fmax(worst, fabs(dr[k] - fd) / (fabs(fd) + 1e-3));
            assert_near(dr[k], fd, 1e-5 + 1e-5 * fabs(fd));
            fd = tu_central(ref_cayley_objective, &c, c.x + k, FD_H);
            assert_near(R[k] * a[0] + R[3 + k] * a[1] + R[6 + k] * a[2], fd, 1e-6);
        }
    }
    print_message("cayley map: worst relative gradient error %.2e\n", worst);
}

/* V = M⁻¹ U per level and transition: applying M to V gives U back. */
static void test_solve(void **state)
{
    (void)state;
    for (int rot = TCB_PDG_RELEASED; rot <= TCB_PDG_CAYLEY; rot++) {
        tcb_pdg_fields f = make((tcb_pdg_rotation)rot);
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
                tcb_sobolev_apply(&f.sobolev[l], f.C, V + at, back + at);
            }
        for (size_t i = 0; i < nv; i++) assert_near(back[i], U[i], 1e-5);
        /* level 0, one node: M = I */
        for (size_t i = 0; i < f.off[1]; i++) assert_true(V[i] == U[i]);
        free(U), free(V), free(back), free(scratch);
        tcb_pdg_fields_free(&f);
    }
}

int main(void)
{
#define FIELD(label, ...) {.name = label, .test_func = test_field, .initial_state = &(kase){__VA_ARGS__}}
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_layout),
                                       FIELD("released", TCB_PDG_RELEASED, 0, 1),
                                       FIELD("cayley", TCB_PDG_CAYLEY, 0, 3),
                                       FIELD("cayley, carried", TCB_PDG_CAYLEY, 1, 4),
                                       cmocka_unit_test(test_cayley_map),
                                       cmocka_unit_test(test_solve)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
