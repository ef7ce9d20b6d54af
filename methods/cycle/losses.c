/* CC's training losses with their gradient. Three passes over the
 * (pair, shape) blocks: nearest-neighbour maps, partial sums, gradients.
 * Every pass writes only its own block's slots and the reductions over
 * blocks run serially in a fixed order, so results do not depend on the
 * OpenMP thread count or schedule. Distances and differences are
 * re-evaluated in double from the float points. */
#include "methods/cycle/losses.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "tcb/nn.h"

const int tcb_cc_pairs[TCB_CC_PAIRS][2] = {{0, 1}, {1, 0}, {1, 2}, {2, 1}, {2, 0}, {0, 2}};

int tcb_cc_pair_index(int s, int t)
{
    for (int k = 0; k < TCB_CC_PAIRS; k++)
        if (tcb_cc_pairs[k][0] == s && tcb_cc_pairs[k][1] == t) return k;
    return -1;
}

/* CC's L2 adds this under the square root (keeps √ differentiable at 0). */
#define RMS_EPS 1e-8

/* A cycle: start at point m of P_start, follow the NN maps of the hop
 * pairs, compare the final pair's deformation at the point reached with
 * the start point. Cycles 0..5 are cycle-2 (one hop, pair k), 6..11
 * cycle-3 (two hops, orientation i→j→l with k = (i→j)). */
#define N_CYCLES (2 * TCB_CC_PAIRS)

typedef struct {
    int start, n_hops, hops[2], final;
} cycle;

struct tcb_cc_losses {
    int max_batch, n;
    int32_t *fwd;        /* [6][B][N]: NN in P_t of D_k[b][m] (CC's idx1) */
    int32_t *bwd;        /* [6][B][N]: NN in D_k[b] of P_t[b][q] (CC's idx2) */
    double *chamfer_sum; /* [6][B]: Σ_q √min_m |D_k[b][m] − q|² */
    double *cycle_sum;   /* [12][B]: Σ_{m,xyz} (cycle image − start)² */
    double *grad;        /* [6][B][N][3]: ∂total/∂D in double, then rounded to gD */
    tcb_error *errs;     /* [6][B]: one per NN task, reported in block order */
    int have_maps;       /* fwd holds the maps of a successful eval */
    int last_batch;
};

/* One call's view of the inputs. */
typedef struct {
    const float *P, *D;
    int B, N;
    tcb_cc_losses *ws;
    cycle cycles[N_CYCLES];
} batch;

static cycle cycle2_of(int k)
{
    int s = tcb_cc_pairs[k][0], t = tcb_cc_pairs[k][1];
    return (cycle){s, 1, {k, -1}, tcb_cc_pair_index(t, s)};
}

static cycle cycle3_of(int k)
{
    int i = tcb_cc_pairs[k][0], j = tcb_cc_pairs[k][1], l = 3 - i - j;
    return (cycle){i, 2, {k, tcb_cc_pair_index(j, l)}, tcb_cc_pair_index(l, i)};
}

static const float *cloud(const batch *x, int i, int b)
{
    return x->P + ((size_t)i * x->B + b) * x->N * 3;
}

static const float *deformed(const batch *x, int k, int b)
{
    return x->D + ((size_t)k * x->B + b) * x->N * 3;
}

static size_t block(const batch *x, int k, int b)
{
    return ((size_t)k * x->B + b) * x->N;
}

static double dist2(const float *p, const float *q)
{
    double d2 = 0.0;
    for (int c = 0; c < 3; c++) d2 += ((double)p[c] - q[c]) * ((double)p[c] - q[c]);
    return d2;
}

/* ---- pass 1: nearest-neighbour maps ------------------------------------ */

static int match_block(batch *x, int k, int b, tcb_error *err)
{
    const float *d = deformed(x, k, b), *target = cloud(x, tcb_cc_pairs[k][1], b);
    int32_t *fwd = x->ws->fwd + block(x, k, b), *bwd = x->ws->bwd + block(x, k, b);
    int rc = tcb_nn_nearest(target, x->N, d, x->N, fwd, NULL, err);
    if (!rc) rc = tcb_nn_nearest(d, x->N, target, x->N, bwd, NULL, err);
    if (rc)
        tcb_error_prefix(err, "cc losses, pair %d->%d of shape %d: ", tcb_cc_pairs[k][0],
                         tcb_cc_pairs[k][1], b);
    return rc;
}

static int match_all(batch *x, tcb_error *err)
{
    int tasks = TCB_CC_PAIRS * x->B;
    tcb_error *errs = x->ws->errs;
#pragma omp parallel for schedule(dynamic, 1)
    for (int task = 0; task < tasks; task++) {
        errs[task].code = TCB_OK;
        match_block(x, task / x->B, task % x->B, &errs[task]);
    }
    /* The first failing block in block order: the same error whatever ran first. */
    for (int task = 0; task < tasks; task++)
        if (errs[task].code) return tcb_fail(err, errs[task].code, "%s", errs[task].msg);
    return TCB_OK;
}

/* ---- pass 2: partial sums ---------------------------------------------- */

/* The point of P_end reached from point m of P_start along the hops. */
static int32_t walk(const batch *x, const cycle *cy, int b, int32_t m)
{
    for (int h = 0; h < cy->n_hops; h++) m = x->ws->fwd[block(x, cy->hops[h], b) + m];
    return m;
}

static double chamfer_block(const batch *x, int k, int b)
{
    const float *d = deformed(x, k, b), *target = cloud(x, tcb_cc_pairs[k][1], b);
    const int32_t *bwd = x->ws->bwd + block(x, k, b);
    double s = 0.0;
    for (int q = 0; q < x->N; q++) s += sqrt(dist2(d + 3 * (size_t)bwd[q], target + 3 * (size_t)q));
    return s;
}

static double cycle_block(const batch *x, const cycle *cy, int b)
{
    const float *start = cloud(x, cy->start, b), *end = deformed(x, cy->final, b);
    double s = 0.0;
    for (int m = 0; m < x->N; m++)
        s += dist2(end + 3 * (size_t)walk(x, cy, b, m), start + 3 * (size_t)m);
    return s;
}

static void sum_all(batch *x)
{
    int tasks = TCB_CC_PAIRS * x->B;
    tcb_cc_losses *ws = x->ws;
#pragma omp parallel for schedule(static)
    for (int task = 0; task < tasks; task++) {
        int k = task / x->B, b = task % x->B;
        ws->chamfer_sum[task] = chamfer_block(x, k, b);
        ws->cycle_sum[task] = cycle_block(x, &x->cycles[k], b);
        ws->cycle_sum[tasks + task] = cycle_block(x, &x->cycles[TCB_CC_PAIRS + k], b);
    }
}

/* Σ over shapes in order; sums [B]. */
static double over_shapes(const double *sums, int B)
{
    double s = 0.0;
    for (int b = 0; b < B; b++) s += sums[b];
    return s;
}

/* The terms from the partial sums; rms [12] gets each cycle's RMS, which
 * the gradient scales need. */
static void reduce(const batch *x, const tcb_cc_loss_weights *w, tcb_cc_loss_terms *t,
                   double *rms)
{
    double points = (double)x->B * x->N;
    t->chamfer = t->cycle2 = t->cycle3 = 0.0;
    for (int k = 0; k < TCB_CC_PAIRS; k++)
        t->chamfer += over_shapes(x->ws->chamfer_sum + (size_t)k * x->B, x->B) / points / 6.0;
    for (int c = 0; c < N_CYCLES; c++) {
        double mean = over_shapes(x->ws->cycle_sum + (size_t)c * x->B, x->B) / (3.0 * points);
        rms[c] = sqrt(mean + RMS_EPS);
        if (c < TCB_CC_PAIRS) t->cycle2 += rms[c] / 6.0;
        else t->cycle3 += rms[c] / 6.0;
    }
    t->total = w->lambda_chamfer * t->chamfer + w->lambda_cycle2 * t->cycle2 +
               w->lambda_cycle3 * t->cycle3;
}

/* ---- pass 3: gradients, one receiving block (pair r, shape b) at a time -- */

/* g [N][3] += scale · ∂/∂d of Σ_q |d[bwd[q]] − q|: the deformed point nearest
 * to each target point is pulled along the unit vector towards it. At
 * distance exactly 0 that direction is undefined: torch's √ backward
 * gives inf there and inf · 0 = NaN; we take 0 (the point already fits). */
static void chamfer_grad(const batch *x, int r, int b, double scale, double *g)
{
    const float *d = deformed(x, r, b), *target = cloud(x, tcb_cc_pairs[r][1], b);
    const int32_t *bwd = x->ws->bwd + block(x, r, b);
    for (int q = 0; q < x->N; q++) {
        const float *p = d + 3 * (size_t)bwd[q], *t = target + 3 * (size_t)q;
        double len = sqrt(dist2(p, t));
        if (len == 0.0) continue;
        double *gp = g + 3 * (size_t)bwd[q];
        for (int c = 0; c < 3; c++) gp[c] += scale * ((double)p[c] - t[c]) / len;
    }
}

/* g [N][3] += scale · ∂/∂D_final of Σ (image − start)², with the walk's
 * indices held fixed: only the gathered points receive gradient, a point
 * gathered by several starts collects them all. */
static void cycle_grad(const batch *x, const cycle *cy, int b, double scale, double *g)
{
    const float *start = cloud(x, cy->start, b), *end = deformed(x, cy->final, b);
    for (int m = 0; m < x->N; m++) {
        size_t n = 3 * (size_t)walk(x, cy, b, m);
        for (int c = 0; c < 3; c++)
            g[n + c] += scale * 2.0 * ((double)end[n + c] - start[3 * (size_t)m + c]);
    }
}

static void block_grad(const batch *x, int r, int b, const double *cycle_scale,
                       double chamfer_scale, float *gD)
{
    size_t len = 3 * (size_t)x->N, at = 3 * block(x, r, b);
    double *g = x->ws->grad + at;
    memset(g, 0, len * sizeof *g);
    chamfer_grad(x, r, b, chamfer_scale, g);
    for (int c = 0; c < N_CYCLES; c++)
        if (x->cycles[c].final == r) cycle_grad(x, &x->cycles[c], b, cycle_scale[c], g);
    for (size_t i = 0; i < len; i++) gD[at + i] = (float)g[i];
}

static void grad_all(const batch *x, const tcb_cc_loss_weights *w, const double *rms, float *gD)
{
    double points = (double)x->B * x->N, cycle_scale[N_CYCLES];
    /* d/dS √(S/(3BN) + ε) = 1 / (2 · 3BN · RMS), times λ/6 of the term. */
    for (int c = 0; c < N_CYCLES; c++)
        cycle_scale[c] = (c < TCB_CC_PAIRS ? w->lambda_cycle2 : w->lambda_cycle3) / 6.0 /
                         (2.0 * 3.0 * points * rms[c]);
    double chamfer_scale = w->lambda_chamfer / 6.0 / points;
    int tasks = TCB_CC_PAIRS * x->B;
#pragma omp parallel for schedule(static)
    for (int task = 0; task < tasks; task++)
        block_grad(x, task / x->B, task % x->B, cycle_scale, chamfer_scale, gD);
}

/* ---- public ------------------------------------------------------------ */

int tcb_cc_losses_create(int max_batch, int n_points, tcb_cc_losses **out, tcb_error *err)
{
    *out = NULL;
    if (max_batch < 1 || n_points < 1)
        return tcb_fail(err, TCB_ERR_INPUT, "cc losses: empty batch (B=%d N=%d)", max_batch,
                        n_points);
    tcb_cc_losses *ws = calloc(1, sizeof *ws);
    size_t blocks = (size_t)TCB_CC_PAIRS * max_batch, points = blocks * n_points;
    if (ws) {
        ws->max_batch = max_batch, ws->n = n_points;
        ws->fwd = malloc(points * sizeof *ws->fwd);
        ws->bwd = malloc(points * sizeof *ws->bwd);
        ws->chamfer_sum = malloc(blocks * sizeof *ws->chamfer_sum);
        ws->cycle_sum = malloc(2 * blocks * sizeof *ws->cycle_sum);
        ws->grad = malloc(3 * points * sizeof *ws->grad);
        ws->errs = calloc(blocks, sizeof *ws->errs);
    }
    if (!ws || !ws->fwd || !ws->bwd || !ws->chamfer_sum || !ws->cycle_sum || !ws->grad ||
        !ws->errs) {
        tcb_cc_losses_free(ws);
        return tcb_fail(err, TCB_ERR_NOMEM, "cc losses: out of memory (B=%d N=%d)", max_batch,
                        n_points);
    }
    *out = ws;
    return TCB_OK;
}

void tcb_cc_losses_free(tcb_cc_losses *ws)
{
    if (!ws) return;
    free(ws->fwd), free(ws->bwd), free(ws->chamfer_sum), free(ws->cycle_sum), free(ws->grad);
    free(ws->errs);
    free(ws);
}

static int check_args(const tcb_cc_losses *ws, const float *P, const float *D, int B,
                      const tcb_cc_loss_weights *w, const tcb_cc_loss_terms *terms,
                      tcb_error *err)
{
    if (!ws || !P || !D || !w || !terms)
        return tcb_fail(err, TCB_ERR_INPUT, "cc losses: missing argument");
    if (B < 1 || B > ws->max_batch)
        return tcb_fail(err, TCB_ERR_INPUT, "cc losses: batch of %d, workspace holds 1..%d", B,
                        ws->max_batch);
    if (!isfinite(w->lambda_chamfer) || !isfinite(w->lambda_cycle2) ||
        !isfinite(w->lambda_cycle3))
        return tcb_fail(err, TCB_ERR_INPUT, "cc losses: non-finite loss weight");
    return TCB_OK;
}

int tcb_cc_losses_eval(tcb_cc_losses *ws, const float *P, const float *D, int B,
                       const tcb_cc_loss_weights *w, tcb_cc_loss_terms *terms, float *gD,
                       tcb_error *err)
{
    int rc = check_args(ws, P, D, B, w, terms, err);
    if (rc) return rc;
    batch x = {.P = P, .D = D, .B = B, .N = ws->n, .ws = ws};
    for (int k = 0; k < TCB_CC_PAIRS; k++)
        x.cycles[k] = cycle2_of(k), x.cycles[TCB_CC_PAIRS + k] = cycle3_of(k);
    ws->have_maps = 0;
    if ((rc = match_all(&x, err))) return rc;
    ws->have_maps = 1, ws->last_batch = B;
    sum_all(&x);
    double rms[N_CYCLES];
    reduce(&x, w, terms, rms);
    if (gD) grad_all(&x, w, rms, gD);
    return TCB_OK;
}

const int32_t *tcb_cc_losses_matches(const tcb_cc_losses *ws, int k)
{
    if (!ws || !ws->have_maps || k < 0 || k >= TCB_CC_PAIRS) return NULL;
    return ws->fwd + (size_t)k * ws->last_batch * ws->n;
}

double tcb_cc_rms(const float *a, const float *b, size_t n, float *grad_a)
{
    if (n == 0) return 0.0; /* CC's L2 returns 0 for empty tensors */
    double s = 0.0;
    for (size_t i = 0; i < n; i++) s += ((double)a[i] - b[i]) * ((double)a[i] - b[i]);
    double rms = sqrt(s / (double)n + RMS_EPS);
    if (grad_a)
        for (size_t i = 0; i < n; i++)
            grad_a[i] = (float)(((double)a[i] - b[i]) / ((double)n * rms));
    return rms;
}
