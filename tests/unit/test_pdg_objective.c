/* methods/pdg/objective.c against a double reference written here from
 * the method's description (objective.h): the fields' steps through
 * tu_ref_pdg_step (the chains compose them as the release does, a 3×4
 * transform per template vertex, for either rotation), brute-force
 * nearest neighbours, the robust Chamfer's Welsch weights and the
 * catch-up weights recorded at the base point and replayed (the method
 * holds both constant in its gradient). The loss and its parts against the
 * reference, the gradient in every field value against central
 * differences, for a keyframe in the middle (two chains of two steps) and
 * off it (one step and three), in and after the warm-up, with the released
 * rotation and the cayley one; the propagation read-out against the
 * chains; and the cayley variant at r = 0 against the released one. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "methods/pdg/objective.h"
#include "tcb/rng.h"
#include "testutil.h"

enum { NF = 5, LEVELS = 3, NPTS = 14, NV = 6, NE = 12, MAX_CALLS = 64 };
#define FD_H 1e-6
#define ALPHA 0.3
#define EDGE_W 250.0

static const int32_t octa_edges[2 * NE] = {0, 2, 0, 3, 0, 4, 0, 5, 1, 2, 1, 3, 1, 4, 1, 5, 2, 4, 2, 5, 3, 4, 3, 5};

/* ---- the reference, with a tape of the held weights ---------------------- */

typedef struct tape {
    int replay, at;                           /* record at the base point, replay in differences */
    double welsch[MAX_CALLS][2 * (NV + NPTS) + 2 * NPTS];
    double catchup[NF];
} tape;

static double sqd(const double *a, const double *b)
{
    double s = 0;
    for (int k = 0; k < 3; k++) s += (a[k] - b[k]) * (a[k] - b[k]);
    return s;
}

static double ref_rc(tape *tp, const double *X, int nx, const double *P, int np)
{
    double *w = tp->welsch[tp->at++];
    const double *in = tp->replay ? w : NULL;
    double *out = tp->replay ? NULL : w;
    return tu_ref_chamfer_way(X, nx, P, np, in, out) + tu_ref_chamfer_way(P, np, X, nx, in ? in + nx : NULL, out ? out + nx : NULL);
}

/* n points through field g: A' = A·[R | t] (A NULL: the identity, x0 =
 * x), y = A' x0 (methods/pdg/field.h). */
static void ref_move(const tcb_pdg_fields *f, const double *V, int g, const double *x, const double *x0,
                     const double *A, int n, double *A_out, double *y)
{
    for (int p = 0; p < n; p++)
        tu_ref_pdg_step(f, V, g, x + 3 * p, A ? x0 + 3 * p : x + 3 * p, A ? A + 12 * p : NULL, A_out + 12 * p,
                        y + 3 * p);
}

static double ref_edges(const double *x, const double *prev)
{
    double sum = 0;
    for (int e = 0; e < NE; e++) {
        int a = octa_edges[2 * e], b = octa_edges[2 * e + 1];
        sum += fabs(sqrt(sqd(x + 3 * a, x + 3 * b)) - sqrt(sqd(prev + 3 * a, prev + 3 * b)));
    }
    return sum / NE;
}

typedef struct world {
    int key;
    double P[NF][3 * NPTS], v[3 * NV];
} world;

static double ref_loss(const tcb_pdg_fields *f, const double *V, const world *wd, long long epoch, long long epochs,
                       int chains, tape *tp, double parts[3])
{
    tp->at = 0;
    int T = NF - 1, key = wd->key;
    double L_in = 0, y[3 * NPTS], A_in[12 * NPTS];
    for (int g = 0; g < T; g++) {
        int a = g < key ? g + 1 : g, b = g < key ? g : g + 1;
        ref_move(f, V, g, wd->P[a], NULL, NULL, NPTS, A_in, y);
        L_in += ref_rc(tp, y, NPTS, wd->P[b], NPTS) / T;
    }
    parts[0] = L_in, parts[1] = parts[2] = 0;
    if (!chains) return L_in;
    int len[2] = {key, NF - 1 - key}, M = len[0] > len[1] ? len[0] : len[1];
    double x[2][NF][3 * NV], A[2][NF][12 * NV];
    for (int k = 0; k < 2; k++) memcpy(x[k][0], wd->v, sizeof wd->v);
    double e = 1 - sqrt((double)epoch / epochs), s = 1, S = 0;
    for (int m = 1; m <= M; m++) {
        int live = (len[0] >= m) + (len[1] >= m);
        double CD = 0, E = 0;
        for (int k = 0; k < 2; k++) {
            if (len[k] < m) continue;
            int dir = k ? 1 : -1, g = dir < 0 ? key - m : key + m - 1, t = dir < 0 ? key - m : key + m;
            ref_move(f, V, g, x[k][m - 1], wd->v, m > 1 ? A[k][m - 1] : NULL, NV, A[k][m], x[k][m]);
            CD += ref_rc(tp, x[k][m], NV, wd->P[t], NPTS) / live;
            E += ref_edges(x[k][m], x[k][m - 1]) / live;
        }
        if (!tp->replay) tp->catchup[m] = pow(s, e);
        parts[1] += tp->catchup[m] * CD / M;
        parts[2] += EDGE_W * E / M;
        S += tp->catchup[m] * CD;
        s /= fmax(1, 1 + S - L_in);
    }
    return L_in + parts[1] + parts[2];
}

/* ---- the case ----------------------------------------------------------- */

static void make_world(tcb_rng *rng, int key, world *wd, float P[NF][3 * NPTS], float v[3 * NV])
{
    wd->key = key;
    const double octa[3 * NV] = {1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1};
    for (int i = 0; i < 3 * NV; i++) v[i] = (float)(0.45 * octa[i] + 0.05 * (tcb_rng_uniform(rng) - 0.5));
    for (int t = 0; t < NF; t++)
        for (int i = 0; i < 3 * NPTS; i++) P[t][i] = (float)(0.9 * (tcb_rng_uniform(rng) - 0.5) + 0.02 * t);
    for (int i = 0; i < 3 * NV; i++) wd->v[i] = v[i];
    for (int t = 0; t < NF; t++)
        for (int i = 0; i < 3 * NPTS; i++) wd->P[t][i] = P[t][i];
}

/* The problem over a world: its frames' indexes and the template's edges. */
typedef struct fixture {
    world wd;
    float P[NF][3 * NPTS], v[3 * NV], len[NE];
    const float *pts[NF];
    const tcb_nn *idx[NF];
    tcb_nn *own[NF];
    int np[NF];
    tcb_pdg_problem p;
} fixture;

static void fixture_build(fixture *fx, tcb_rng *rng, int key)
{
    tcb_error err = {0};
    make_world(rng, key, &fx->wd, fx->P, fx->v);
    for (int e = 0; e < NE; e++) {
        int a = octa_edges[2 * e], b = octa_edges[2 * e + 1];
        fx->len[e] = (float)sqrt(sqd(fx->wd.v + 3 * a, fx->wd.v + 3 * b));
    }
    for (int t = 0; t < NF; t++) {
        fx->pts[t] = fx->P[t], fx->np[t] = NPTS;
        assert_int_equal(tcb_nn_build(fx->P[t], NPTS, &fx->own[t], &err), TCB_OK);
        fx->idx[t] = fx->own[t];
    }
    fx->p = (tcb_pdg_problem){NF, key, fx->pts, fx->np, fx->idx, NV, fx->v, NE, octa_edges, fx->len};
}

static void fixture_free(fixture *fx)
{
    for (int t = 0; t < NF; t++) tcb_nn_free(fx->own[t]);
}

static const tcb_pdg_weights weights = {EDGE_W, ALPHA, 101};
static const long long epochs = 400;

static void check_case(int key, long long epoch, tcb_pdg_rotation rotation)
{
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, (uint64_t)(10 * key + (epoch > 100)), "pdg-objective");
    tcb_pdg_fields f;
    tcb_error err = {0};
    assert_int_equal(tcb_pdg_fields_init(&f, LEVELS, NF - 1, rotation, 0.25, 1.5, &err), TCB_OK);
    static fixture fx;
    fixture_build(&fx, &rng, key);
    const world *wd = &fx.wd;
    const float *v = fx.v;
    size_t nval = f.off[LEVELS];
    float *V = tu_falloc(nval), *dV = tu_falloc(nval);
    tu_fill_uniform(&rng, V, nval, -1.5, 1.5);
    tcb_pdg_loss loss;
    assert_int_equal(tcb_pdg_loss_grad(&f, V, &fx.p, &weights, epoch, epochs, &loss, dV, &err), TCB_OK);
    static tape tp;
    memset(&tp, 0, sizeof tp);
    double *Vd = tu_to_double(V, nval), parts[3];
    int chains = epoch >= 101;
    double ref = ref_loss(&f, Vd, wd, epoch, epochs, chains, &tp, parts);
    print_message("%s, key %d, epoch %lld: loss %.6f (input %.6f, pred %.6f, edge %.6f), reference %.6f\n",
                  tcb_pdg_rotation_names[rotation], key, epoch, loss.total, loss.input, loss.pred, loss.edge, ref);
    assert_near(loss.total, ref, 1e-5 * fabs(ref));
    assert_near(loss.input, parts[0], 1e-5 * fabs(parts[0]));
    assert_near(loss.pred, parts[1], 1e-5 * fabs(parts[1]) + 1e-12);
    assert_near(loss.edge, parts[2], 1e-5 * fabs(parts[2]) + 1e-12);
    if (chains) {
        assert_true(loss.pred > 0 && loss.edge > 0);
        double least = 1; /* the catch-up must be at work: a later step weighs less */
        for (int m = 2; m < NF; m++)
            if (tp.catchup[m] > 0) least = fmin(least, tp.catchup[m]);
        print_message("  smallest catch-up weight %.4f\n", least);
        assert_true(least < 0.999); /* measured 0.9935 (keyframe 2) and 0.867 (keyframe 1) */
    }
    tp.replay = 1;
    double worst = 0;
    for (size_t i = 0; i < nval; i++) {
        double keep = Vd[i];
        Vd[i] = keep + FD_H;
        double lp = ref_loss(&f, Vd, wd, epoch, epochs, chains, &tp, parts);
        Vd[i] = keep - FD_H;
        double lm = ref_loss(&f, Vd, wd, epoch, epochs, chains, &tp, parts);
        Vd[i] = keep;
        double fd = (lp - lm) / (2 * FD_H), tol = 2e-4 * fabs(fd) + 2e-5;
        worst = fmax(worst, fabs(dV[i] - fd) / (fabs(fd) + 1e-3));
        if (!(fabs(dV[i] - fd) <= tol)) fail_msg("dV[%zu] = %.8g, central difference %.8g", i, dV[i], fd);
    }
    print_message("  gradient: %zu values, worst relative %.2e\n", nval, worst);
    /* the read-out: the chains' end points in every frame, the template at the keyframe */
    float X[NF][3 * NV];
    assert_int_equal(tcb_pdg_propagate(&f, V, &fx.p, &X[0][0], &err), TCB_OK);
    double y[3 * NV], x0[3 * NV], A[12 * NV], A_next[12 * NV];
    for (int i = 0; i < 3 * NV; i++) assert_true(X[key][i] == v[i]);
    for (int t = 0; t < NF; t++) {
        if (t == key) continue;
        int dir = t < key ? -1 : 1;
        for (int i = 0; i < 3 * NV; i++) x0[i] = v[i];
        for (int m = 1; m <= abs(t - key); m++) {
            ref_move(&f, Vd, dir < 0 ? key - m : key + m - 1, x0, wd->v, m > 1 ? A : NULL, NV, A_next, y);
            memcpy(x0, y, sizeof y), memcpy(A, A_next, sizeof A);
        }
        for (int i = 0; i < 3 * NV; i++) assert_near(X[t][i], y[i], 1e-5);
    }
    fixture_free(&fx);
    free(V), free(dV), free(Vd);
    tcb_pdg_fields_free(&f);
}

typedef struct kase {
    int key;
    long long epoch;
    tcb_pdg_rotation rotation;
} kase;

static void test_case(void **state)
{
    const kase *k = *state;
    check_case(k->key, k->epoch, k->rotation);
}

/* At r = 0 the Cayley rotation is the identity, so the cayley variant is
 * the translation-only one: the same loss and translation gradients (up
 * to the chain's rounding: it adds the steps into A where the released
 * one adds them to the points) — and, unlike the release's rotation, its
 * rotation channels do get a gradient there. */
static void test_cayley_at_zero(void **state)
{
    (void)state;
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 7, "pdg-objective");
    static fixture fx;
    fixture_build(&fx, &rng, 2);
    tcb_pdg_fields fr, fc;
    tcb_error err = {0};
    assert_int_equal(tcb_pdg_fields_init(&fr, LEVELS, NF - 1, TCB_PDG_RELEASED, 0.25, 1.5, &err), TCB_OK);
    assert_int_equal(tcb_pdg_fields_init(&fc, LEVELS, NF - 1, TCB_PDG_CAYLEY, 0.25, 1.5, &err), TCB_OK);
    size_t nr = fr.off[LEVELS], nc = fc.off[LEVELS], nodes = nr / 3;
    float *Vr = tu_falloc(nr), *Vc = tu_falloc(nc), *dr = tu_falloc(nr), *dc = tu_falloc(nc);
    tu_fill_uniform(&rng, Vr, nr, -1.5, 1.5);
    for (size_t i = 0; i < nodes; i++) /* both level-major with the same nodes in order: r = 0, the same t */
        for (int k = 0; k < 3; k++) Vc[6 * i + 3 + k] = Vr[3 * i + k];
    tcb_pdg_loss lr, lc;
    assert_int_equal(tcb_pdg_loss_grad(&fr, Vr, &fx.p, &weights, 150, epochs, &lr, dr, &err), TCB_OK);
    assert_int_equal(tcb_pdg_loss_grad(&fc, Vc, &fx.p, &weights, 150, epochs, &lc, dc, &err), TCB_OK);
    print_message("released %.9f, cayley at r = 0 %.9f\n", lr.total, lc.total);
    assert_true(lc.input == lr.input); /* the input term has no chain: R = I exactly */
    assert_near(lc.total, lr.total, 1e-6 * lr.total);
    double rot = 0.0, most = 0.0;
    for (size_t i = 0; i < nodes; i++)
        for (int k = 0; k < 3; k++) {
            most = fmax(most, fabs(dr[3 * i + k]));
            rot = fmax(rot, fabs(dc[6 * i + k]));
        }
    for (size_t i = 0; i < nodes; i++)
        for (int k = 0; k < 3; k++) assert_near(dc[6 * i + 3 + k], dr[3 * i + k], 1e-5 * most);
    print_message("  largest translation gradient %.4g, rotation gradient %.4g\n", most, rot);
    assert_true(rot > 1e-3 * most);
    fixture_free(&fx);
    free(Vr), free(Vc), free(dr), free(dc);
    tcb_pdg_fields_free(&fr), tcb_pdg_fields_free(&fc);
}

int main(void)
{
#define CASE(label, ...) {.name = label, .test_func = test_case, .initial_state = &(kase){__VA_ARGS__}}
    const struct CMUnitTest tests[] = {CASE("middle keyframe", 2, 150, TCB_PDG_RELEASED),
                                       CASE("keyframe off centre", 1, 300, TCB_PDG_RELEASED),
                                       CASE("warm-up", 3, 20, TCB_PDG_RELEASED),
                                       CASE("cayley, middle keyframe", 2, 150, TCB_PDG_CAYLEY),
                                       CASE("cayley, keyframe off centre", 1, 300, TCB_PDG_CAYLEY),
                                       cmocka_unit_test(test_cayley_at_zero)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
