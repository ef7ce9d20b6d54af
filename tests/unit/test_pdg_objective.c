/* methods/pdg/objective.c against a double reference written here from
 * the method's description (objective.h): the fields through
 * tu_ref_trilinear, brute-force nearest neighbours, the robust Chamfer's
 * Welsch weights and the catch-up weights recorded at the base point and
 * replayed (the method holds both constant in its gradient). The loss and
 * its parts against the reference, the gradient in every field value
 * against central differences, for a keyframe in the middle (two chains of
 * two steps) and off it (one step and three), in and after the warm-up;
 * and the propagation read-out against the chains. */
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

static void ref_move(const tcb_pdg_fields *f, const double *V, int g, const double *x, int n, double *y)
{
    for (int p = 0; p < n; p++) {
        double s[3] = {0, 0, 0}, o[3];
        for (int l = 0; l < f->levels; l++) {
            tu_ref_trilinear(V + f->off[l] + (size_t)g * f->r[l] * f->r[l] * f->r[l] * 3, f->r[l], 3, x + 3 * p, o);
            for (int a = 0; a < 3; a++) s[a] += o[a] / f->levels;
        }
        for (int a = 0; a < 3; a++) y[3 * p + a] = x[3 * p + a] + 0.1 * tanh(s[a]);
    }
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
    double L_in = 0, y[3 * NPTS];
    for (int g = 0; g < T; g++) {
        int a = g < key ? g + 1 : g, b = g < key ? g : g + 1;
        ref_move(f, V, g, wd->P[a], NPTS, y);
        L_in += ref_rc(tp, y, NPTS, wd->P[b], NPTS) / T;
    }
    parts[0] = L_in, parts[1] = parts[2] = 0;
    if (!chains) return L_in;
    int len[2] = {key, NF - 1 - key}, M = len[0] > len[1] ? len[0] : len[1];
    double x[2][NF][3 * NV];
    for (int k = 0; k < 2; k++) memcpy(x[k][0], wd->v, sizeof wd->v);
    double e = 1 - sqrt((double)epoch / epochs), s = 1, S = 0;
    for (int m = 1; m <= M; m++) {
        int live = (len[0] >= m) + (len[1] >= m);
        double CD = 0, E = 0;
        for (int k = 0; k < 2; k++) {
            if (len[k] < m) continue;
            int dir = k ? 1 : -1, g = dir < 0 ? key - m : key + m - 1, t = dir < 0 ? key - m : key + m;
            ref_move(f, V, g, x[k][m - 1], NV, x[k][m]);
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

static void check_case(int key, long long epoch)
{
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, (uint64_t)(10 * key + (epoch > 100)), "pdg-objective");
    tcb_pdg_fields f;
    tcb_error err = {0};
    assert_int_equal(tcb_pdg_fields_init(&f, LEVELS, NF - 1, 0.25, 1.5, &err), TCB_OK);
    world wd;
    float P[NF][3 * NPTS], v[3 * NV], len[NE];
    make_world(&rng, key, &wd, P, v);
    for (int e = 0; e < NE; e++) {
        int a = octa_edges[2 * e], b = octa_edges[2 * e + 1];
        len[e] = (float)sqrt(sqd(wd.v + 3 * a, wd.v + 3 * b));
    }
    const float *pts[NF];
    const tcb_nn *idx[NF];
    tcb_nn *own[NF];
    int np[NF];
    for (int t = 0; t < NF; t++) {
        pts[t] = P[t], np[t] = NPTS;
        assert_int_equal(tcb_nn_build(P[t], NPTS, &own[t], &err), TCB_OK);
        idx[t] = own[t];
    }
    tcb_pdg_problem p = {NF, key, pts, np, idx, NV, v, NE, octa_edges, len};
    tcb_pdg_weights w = {EDGE_W, ALPHA, 101};
    size_t nval = f.off[LEVELS];
    float *V = tu_falloc(nval), *dV = tu_falloc(nval);
    tu_fill_uniform(&rng, V, nval, -1.5, 1.5);
    tcb_pdg_loss loss;
    const long long epochs = 400;
    assert_int_equal(tcb_pdg_loss_grad(&f, V, &p, &w, epoch, epochs, &loss, dV, &err), TCB_OK);
    static tape tp;
    memset(&tp, 0, sizeof tp);
    double *Vd = tu_to_double(V, nval), parts[3];
    int chains = epoch >= 101;
    double ref = ref_loss(&f, Vd, &wd, epoch, epochs, chains, &tp, parts);
    print_message("key %d, epoch %lld: loss %.6f (input %.6f, pred %.6f, edge %.6f), reference %.6f\n", key, epoch,
                  loss.total, loss.input, loss.pred, loss.edge, ref);
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
        double lp = ref_loss(&f, Vd, &wd, epoch, epochs, chains, &tp, parts);
        Vd[i] = keep - FD_H;
        double lm = ref_loss(&f, Vd, &wd, epoch, epochs, chains, &tp, parts);
        Vd[i] = keep;
        double fd = (lp - lm) / (2 * FD_H), tol = 2e-4 * fabs(fd) + 2e-5;
        worst = fmax(worst, fabs(dV[i] - fd) / (fabs(fd) + 1e-3));
        if (!(fabs(dV[i] - fd) <= tol)) fail_msg("dV[%zu] = %.8g, central difference %.8g", i, dV[i], fd);
    }
    print_message("  gradient: %zu values, worst relative %.2e\n", nval, worst);
    /* the read-out: the chains' end points in every frame, the template at the keyframe */
    float X[NF][3 * NV];
    tcb_pdg_propagate(&f, V, &p, &X[0][0]);
    double y[3 * NV], x0[3 * NV];
    for (int i = 0; i < 3 * NV; i++) assert_true(X[key][i] == v[i]);
    for (int t = 0; t < NF; t++) {
        if (t == key) continue;
        int dir = t < key ? -1 : 1;
        for (int i = 0; i < 3 * NV; i++) x0[i] = v[i];
        for (int m = 1; m <= abs(t - key); m++) {
            ref_move(&f, Vd, dir < 0 ? key - m : key + m - 1, x0, NV, y);
            memcpy(x0, y, sizeof y);
        }
        for (int i = 0; i < 3 * NV; i++) assert_near(X[t][i], y[i], 1e-5);
    }
    for (int t = 0; t < NF; t++) tcb_nn_free(own[t]);
    free(V), free(dV), free(Vd);
    tcb_pdg_fields_free(&f);
}

static void test_middle_keyframe(void **state)
{
    (void)state;
    check_case(2, 150);
}

static void test_keyframe_off_centre(void **state)
{
    (void)state;
    check_case(1, 300);
}

static void test_warmup(void **state)
{
    (void)state;
    check_case(3, 20);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_middle_keyframe), cmocka_unit_test(test_keyframe_off_centre),
                                       cmocka_unit_test(test_warmup)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
