/* neural/sobolev.c: the exact solve of (I + λL) v = u on a lattice,
 * checked against conjugate gradient on the sparse matrix written here
 * (run to convergence, and as the reference stops it: ≤ 100 iterations,
 * ‖r‖² < 1e-4), against its own sparse apply, and as the gradient of the
 * parameterisation by central differences of ℓ(u) = Σ a·M⁻¹u in double;
 * for both Laplacians: the graph one (D − A, the DCT's) and pcgrid's, whose
 * diagonal is counted here as pcgrid counts it (each node's occurrences in
 * an edge list holding both directions of every edge). */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "neural/sobolev.h"
#include "tcb/rng.h"
#include "testutil.h"

enum { R = 6, F = 2, NV = R * R * R * F };
#define LAMBDA 0.9

static tcb_sobolev_laplacian kind;
static double diag[R * R * R]; /* L's diagonal */

/* The diagonal as each Laplacian defines it: the graph's counts a node's
 * neighbours; pcgrid's counts the node's occurrences in the list of
 * directed edges (node, neighbour) over all nodes, both columns. */
static void count_diagonal(void)
{
    for (int i = 0; i < R * R * R; i++) diag[i] = 0;
    for (int z = 0; z < R; z++)
        for (int y = 0; y < R; y++)
            for (int x = 0; x < R; x++)
                for (int a = 0; a < 3; a++)
                    for (int s = -1; s <= 1; s += 2) {
                        int c[3] = {x, y, z};
                        c[a] += s;
                        if (c[a] < 0 || c[a] >= R) continue;
                        int from = (z * R + y) * R + x, to = (c[2] * R + c[1]) * R + c[0];
                        diag[from] += 1;                         /* the edge's first column */
                        if (kind == TCB_SOBOLEV_PCGRID) diag[to] += 1; /* and its second */
                    }
}

static int setup_pcgrid(void **state)
{
    (void)state;
    kind = TCB_SOBOLEV_PCGRID;
    count_diagonal();
    return 0;
}

static int setup_graph(void **state)
{
    (void)state;
    kind = TCB_SOBOLEV_GRAPH;
    count_diagonal();
    return 0;
}

/* y = M x in double, the lattice's 6-neighbour Laplacian written out. */
static void ref_apply(const double *x, double *y)
{
    for (int z = 0; z < R; z++)
        for (int yy = 0; yy < R; yy++)
            for (int xx = 0; xx < R; xx++)
                for (int f = 0; f < F; f++) {
                    int c[3] = {xx, yy, z};
                    size_t node = ((size_t)z * R + yy) * R + xx, i = node * F + f;
                    double acc = x[i] + LAMBDA * diag[node] * x[i];
                    for (int a = 0; a < 3; a++)
                        for (int s = -1; s <= 1; s += 2) {
                            int cc[3] = {c[0], c[1], c[2]};
                            cc[a] += s;
                            if (cc[a] < 0 || cc[a] >= R) continue;
                            size_t nb = ((size_t)cc[2] * R + cc[1]) * R + cc[0];
                            acc -= LAMBDA * x[nb * F + f];
                        }
                    y[i] = acc;
                }
}

/* CG from zero on M x = b, per feature column as the reference batches it
 * (one system per column); stops when every column's ‖r‖² < tol or after
 * max_it iterations. */
static void ref_cg(const double *b, double *x, double tol, int max_it)
{
    double r[NV], p[NV], Ap[NV];
    for (int i = 0; i < NV; i++) x[i] = 0.0, r[i] = b[i], p[i] = b[i];
    double rs[F] = {0};
    for (int i = 0; i < NV; i++) rs[i % F] += r[i] * r[i];
    for (int it = 0; it < max_it; it++) {
        ref_apply(p, Ap);
        double pap[F] = {0}, rs_new[F] = {0};
        for (int i = 0; i < NV; i++) pap[i % F] += p[i] * Ap[i];
        for (int i = 0; i < NV; i++) {
            double alpha = rs[i % F] / pap[i % F];
            x[i] += alpha * p[i];
            r[i] -= alpha * Ap[i];
        }
        for (int i = 0; i < NV; i++) rs_new[i % F] += r[i] * r[i];
        int done = 1;
        for (int f = 0; f < F; f++) done &= rs_new[f] < tol;
        if (done) return;
        for (int i = 0; i < NV; i++) p[i] = r[i] + rs_new[i % F] / rs[i % F] * p[i];
        for (int f = 0; f < F; f++) rs[f] = rs_new[f];
    }
}

static tcb_sobolev make(void)
{
    tcb_sobolev s;
    tcb_error err = {0};
    assert_int_equal(tcb_sobolev_init(&s, R, LAMBDA, kind, &err), TCB_OK);
    return s;
}

static void test_solve_matches_cg(void **state)
{
    (void)state;
    tcb_sobolev s = make();
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 3, "sobolev");
    float u[NV], v[NV];
    double scratch[NV], x[NV], xr[NV];
    tu_fill_uniform(&rng, u, NV, -1.0, 1.0);
    tcb_sobolev_solve(&s, F, u, v, scratch);
    double *ud = tu_to_double(u, NV);
    ref_cg(ud, x, 1e-28, 10 * NV);
    double worst = 0.0, worst_ref = 0.0, scale = 0.0;
    ref_cg(ud, xr, 1e-4, 100);
    for (int i = 0; i < NV; i++) {
        worst = fmax(worst, fabs(v[i] - x[i]));
        worst_ref = fmax(worst_ref, fabs(xr[i] - x[i]));
        scale = fmax(scale, fabs(x[i]));
    }
    /* Exact to float rounding; the reference's stopping rule leaves more. */
    assert_true(worst <= 1e-6 * scale);
    assert_true(worst_ref <= 5e-3 * scale); /* the two agree to the reference's tolerance */
    printf("%s: exact solve vs converged CG: %.2e; the reference's CG (<= 100 it, |r|^2 < 1e-4) vs "
           "converged: %.2e (max |v| %.3f)\n", tcb_sobolev_laplacian_names[kind], worst, worst_ref, scale);
    free(ud);
    tcb_sobolev_free(&s);
}

static void test_apply_then_solve(void **state)
{
    (void)state;
    tcb_sobolev s = make();
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 4, "sobolev");
    float v[NV], u[NV], back[NV];
    double scratch[NV], ref[NV];
    tu_fill_uniform(&rng, v, NV, -1.0, 1.0);
    tcb_sobolev_apply(&s, F, v, u);
    double *vd = tu_to_double(v, NV);
    ref_apply(vd, ref);
    for (int i = 0; i < NV; i++) assert_near(u[i], ref[i], 1e-5);
    tcb_sobolev_solve(&s, F, u, back, scratch);
    for (int i = 0; i < NV; i++) assert_near(back[i], v[i], 1e-5);
    free(vd);
    tcb_sobolev_free(&s);
}

/* The gradient of ℓ(u) = Σ a·v(u), v = M⁻¹u, is M⁻¹a: the solve applied to
 * a, against central differences of ℓ with v from converged CG. */
static void test_gradient(void **state)
{
    (void)state;
    tcb_sobolev s = make();
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 5, "sobolev");
    float a[NV], u[NV], g[NV];
    double scratch[NV], x[NV];
    tu_fill_uniform(&rng, a, NV, -1.0, 1.0);
    tu_fill_uniform(&rng, u, NV, -1.0, 1.0);
    tcb_sobolev_solve(&s, F, a, g, scratch);
    double *ud = tu_to_double(u, NV);
    const double h = 1e-3; /* ℓ is linear in u: no truncation error */
    for (int e = 0; e < NV; e += 7) {
        double l[2];
        for (int side = 0; side < 2; side++) {
            double keep = ud[e];
            ud[e] = keep + (side ? -h : h);
            ref_cg(ud, x, 1e-28, 10 * NV);
            ud[e] = keep;
            l[side] = 0.0;
            for (int i = 0; i < NV; i++) l[side] += a[i] * x[i];
        }
        assert_near(g[e], (l[0] - l[1]) / (2.0 * h), 1e-6);
    }
    free(ud);
    tcb_sobolev_free(&s);
}

static void test_single_node_and_bad_input(void **state)
{
    (void)state;
    tcb_sobolev s;
    tcb_error err = {0};
    assert_int_equal(tcb_sobolev_init(&s, 1, 0.4, kind, &err), TCB_OK);
    float u[2] = {0.25f, -3.0f}, v[2];
    double scratch[2];
    tcb_sobolev_solve(&s, 2, u, v, scratch);
    assert_near(v[0], 0.25, 1e-7); /* one node: L = 0, M = I */
    assert_near(v[1], -3.0, 1e-6);
    tcb_sobolev_free(&s);
    assert_int_equal(tcb_sobolev_init(&s, 0, 0.4, kind, &err), TCB_ERR_INPUT);
    assert_int_equal(tcb_sobolev_init(&s, 4, -1.0, kind, &err), TCB_ERR_INPUT);
    assert_int_equal(tcb_sobolev_init(&s, 4, NAN, kind, &err), TCB_ERR_INPUT);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_solve_matches_cg), cmocka_unit_test(test_apply_then_solve),
        cmocka_unit_test(test_gradient), cmocka_unit_test(test_single_node_and_bad_input)};
    int failed = cmocka_run_group_tests_name("pcgrid's 2D - A", tests, setup_pcgrid, NULL);
    return failed + cmocka_run_group_tests_name("graph D - A", tests, setup_graph, NULL);
}
