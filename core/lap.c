/* Exact dense linear assignment: Jonker–Volgenant (1987).
 *
 * The solver keeps column potentials v[j] and a partial assignment with one
 * invariant: every assigned row sits on a column that minimises its reduced
 * cost c[i][j] − v[j] (that minimum is the row potential u[i], never stored).
 * Three warm-start phases set up v and assign most rows cheaply:
 *   1. column reduction: v[j] = min_i c[i][j], each column offered to its
 *      argmin row;
 *   2. reduction transfer: a row that got exactly one column lowers that
 *      column's v until the row's runner-up column ties with it;
 *   3. augmenting row reduction (JV's two passes): a free row takes its best
 *      column, lowering v there so its runner-up ties, and evicts the owner.
 * Each step keeps the invariant, so nothing is lost: the rows still free are
 * then assigned one at a time by a shortest augmenting path (Dijkstra over
 * columns, reduced costs ≥ 0, as in Crouse 2016 / scipy's
 * linear_sum_assignment) and the dual update that restores the invariant.
 * When no row is free the invariant plus complementary slackness make the
 * assignment optimal. The warm start only changes how much work the paths
 * do.
 *
 * Cost model: every step reads whole cost rows (n doubles, contiguous), and
 * those reads are memory-bound (~1 ns per entry measured at n = 5000, with
 * the loops vectorized), so the time is the number of row reads. At
 * n = 5000, uniform costs: ~22k reads in phases 2–3, ~85k in paths; squared
 * distances between 3-D clouds: ~23k and ~307k (JV's phase 3 saves reads
 * there only on the uniform case, ~18%).
 *
 * Floating point: reduced costs are differences of doubles, so ties are
 * decided exactly as the arithmetic rounds them and the optimum is exact up
 * to the rounding of those differences (a few ulps of the potentials per
 * path). Two places guard against rounding instead of trusting exact
 * arithmetic: a potential decrease that rounds to nothing in phase 3 counts
 * as a tie (JV's loop could otherwise bounce a row pair forever), and the
 * immediate re-processing of evicted rows in phase 3 is budgeted (it is a
 * heuristic; rows left over simply go to phase 4).
 *
 * Memory: O(n) beyond the caller's matrix; rows are read contiguously. */
#include "tcb/lap.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Potentials are sums of up to ~2n costs; bounding |c| keeps every sum and
 * difference far from overflow (2·INT_MAX·1e150 ≈ 4e159 ≪ DBL_MAX). */
#define LAP_COST_MAX 1e150

/* Lanes of the row loops (row_argmin, relax): two AVX2 registers of doubles.
 * With 4 lanes gcc 12 picks 16-byte vectors and the loop runs at scalar
 * speed; with 8 lanes and 64-bit indices throughout it uses 32-byte vectors,
 * 2.5x faster than the branchy scalar loop. Any width is correct. */
#define LANES 8

/* Phase-3 evictions re-processed at once per pass, in units of n. Budgets
 * 1–8 gave the same total row reads at n = 5000 (uniform and squared
 * distances), 16 and 32 more; unbounded (JV's original) made the whole
 * solve 3–10x slower at n = 2500. */
#define ARR_BUDGET_PER_ROW 4

typedef struct lap {
    int n;
    const double *c;       /* [n][n] costs, row-major */
    double *v;             /* [n] column potentials */
    int32_t *rowsol;       /* [n] column of each row, -1 when free */
    int32_t *colsol;       /* [n] row of each column, -1 when free */
    int32_t *free_rows;    /* [n] the nfree rows still unassigned */
    int nfree;
    double *d;             /* [n] path scratch: distance to each column */
    int64_t *pred;         /* [n] path scratch: row before each column */
    int32_t *ready;        /* [n] path scratch: columns scanned, in order */
    int32_t *count;        /* [n] phase-1 scratch: columns offered to each row */
    double *dready, *vready; /* [n] path scratch: d and v of the scanned columns */
    int32_t *free_cols;    /* [n] the nfree_cols columns still unassigned (phase 4) */
    int nfree_cols;
} lap;

/* Index of the first entry of x[0..len) that is NaN, infinite or beyond
 * ±LAP_COST_MAX, or len. Row by row, the flag loop vectorizes. */
static size_t first_bad(const double *x, size_t len)
{
    int bad = 0;
    for (size_t k = 0; k < len; k++) bad |= !(fabs(x[k]) <= LAP_COST_MAX); /* NaN fails <= */
    if (!bad) return len;
    size_t k = 0;
    while (fabs(x[k]) <= LAP_COST_MAX) k++;
    return k;
}

static int check_costs(const double *c, int n_rows, int n_cols, const int32_t *out,
                       tcb_error *err)
{
    if (!c || !out) return tcb_fail(err, TCB_ERR_INPUT, "lap: NULL cost matrix or output");
    if (n_rows <= 0 || n_cols <= 0)
        return tcb_fail(err, TCB_ERR_INPUT, "lap: empty cost matrix (%dx%d)", n_rows, n_cols);
    if (n_rows != n_cols)
        return tcb_fail(err, TCB_ERR_INPUT,
                        "lap: cost matrix is %dx%d; only square problems are supported",
                        n_rows, n_cols);
    for (int i = 0; i < n_rows; i++) {
        const double *ci = c + (size_t)i * n_cols;
        size_t j = first_bad(ci, (size_t)n_cols);
        if (j < (size_t)n_cols)
            return tcb_fail(err, TCB_ERR_INPUT,
                            "lap: cost at (row %d, col %zu) is %g; costs must be finite and "
                            "within ±%g",
                            i, j, ci[j], LAP_COST_MAX);
    }
    return TCB_OK;
}

/* Phase 1. argmin: [n] scratch; matches[i]: [n] columns offered to row i. */
static void column_reduction(lap *s, int32_t *argmin, int32_t *matches)
{
    int n = s->n;
    memcpy(s->v, s->c, (size_t)n * sizeof *s->v);
    memset(argmin, 0, (size_t)n * sizeof *argmin);
    for (int i = 1; i < n; i++) {
        const double *ci = s->c + (size_t)i * n;
        for (int j = 0; j < n; j++)
            if (ci[j] < s->v[j]) s->v[j] = ci[j], argmin[j] = i;
    }
    memset(matches, 0, (size_t)n * sizeof *matches);
    for (int j = 0; j < n; j++) {
        int i = argmin[j];
        if (matches[i]++ == 0) s->rowsol[i] = j, s->colsol[j] = i;
    }
}

/* Lane holding the least (value, index) of best/arg. */
static int lane_pick(const double *best, const int64_t *arg)
{
    int m = 0;
    for (int l = 1; l < LANES; l++)
        if (best[l] < best[m] || (best[l] == best[m] && arg[l] < arg[m])) m = l;
    return m;
}

/* One column of row_argmin(), in lane l (each lane keeps its first minimum).
 * Branch-free: arithmetic selects on 64-bit indices vectorize, ?: on them
 * becomes masked stores. */
static inline void argmin_col(const double *restrict ci, const double *restrict v, int64_t skip,
                              int64_t j, double *restrict best, int64_t *restrict arg, int l)
{
    double h = ci[j] - v[j];
    int64_t lower = (h < best[l]) & (j != skip);
    best[l] = lower ? h : best[l];
    arg[l] += lower * (j - arg[l]);
}

/* Least reduced cost ci[j] − v[j] over j ≠ skip (skip may be -1) and its
 * lowest column, in *j (n ≥ 2). */
static double row_argmin(const double *ci, const double *v, int n, int skip, int *j)
{
    const int nb = n - n % LANES;
    double best[LANES];
    int64_t arg[LANES];
    for (int l = 0; l < LANES; l++) best[l] = INFINITY, arg[l] = n;
    for (int b = 0; b < nb; b += LANES) {
#pragma omp simd
        for (int l = 0; l < LANES; l++) argmin_col(ci, v, skip, b + l, best, arg, l);
    }
    for (int k = nb; k < n; k++) argmin_col(ci, v, skip, k, best, arg, k - nb);
    int m = lane_pick(best, arg);
    *j = (int)arg[m];
    return best[m];
}

/* Phase 2; also collects the free rows. */
static void reduction_transfer(lap *s, const int32_t *matches)
{
    int n = s->n, unused;
    s->nfree = 0;
    for (int i = 0; i < n; i++) {
        if (matches[i] == 0) {
            s->free_rows[s->nfree++] = i;
        } else if (matches[i] == 1) {
            int j1 = s->rowsol[i];
            s->v[j1] -= row_argmin(s->c + (size_t)i * n, s->v, n, j1, &unused);
        }
    }
}

/* Phase 3, one pass over the free rows; rows evicted by a strict potential
 * decrease are re-processed at once (while *budget lasts), the others are
 * kept for the next pass. */
static void augmenting_row_reduction(lap *s, long *budget)
{
    int n = s->n, k = 0, nprev = s->nfree, nfree = 0;
    while (k < nprev) {
        int i = s->free_rows[k++];
        const double *ci = s->c + (size_t)i * n;
        int j1, j2;
        double u1 = row_argmin(ci, s->v, n, -1, &j1), u2 = row_argmin(ci, s->v, n, j1, &j2);
        int i0 = s->colsol[j1];
        double vnew = s->v[j1] - (u2 - u1);
        int strict = vnew < s->v[j1]; /* u2 > u1 and the gap survives rounding */
        if (strict) s->v[j1] = vnew;
        else if (i0 >= 0) j1 = j2, i0 = s->colsol[j2]; /* a tie: take the runner-up */
        s->rowsol[i] = j1;
        s->colsol[j1] = i;
        if (i0 >= 0) {
            s->rowsol[i0] = -1;
            /* k-1 held i, already consumed; nfree ≤ k-1 keeps the two ends apart. */
            if (strict && (*budget)-- > 0) s->free_rows[--k] = i0;
            else s->free_rows[nfree++] = i0;
        }
    }
    s->nfree = nfree;
}

/* One column of relax(), in lane l: relax it, then fold it into the lane's
 * running minimum, as argmin_col(). Scanned columns are parked at d = +inf,
 * v = −inf, so ci − v − h = +inf never relaxes them and they are never the
 * minimum. */
static inline void relax_col(const double *restrict ci, const double *restrict v,
                             double *restrict d, int64_t *restrict pred, int64_t i, double h,
                             int64_t j, double *restrict best, int64_t *restrict arg, int l)
{
    double dj = ci[j] - v[j] - h;
    int64_t closer = dj < d[j];
    d[j] = closer ? dj : d[j];
    pred[j] += closer * (i - pred[j]);
    int64_t lower = d[j] < best[l];
    best[l] = lower ? d[j] : best[l];
    arg[l] += lower * (j - arg[l]);
}

/* Relaxes the unscanned columns through row i (h = u[i] minus the distance at
 * which i was reached) and returns the lowest-index unscanned column of least
 * distance. */
static int relax(lap *s, int i, double h)
{
    const int n = s->n, nb = n - n % LANES;
    const double *ci = s->c + (size_t)i * n;
    double best[LANES];
    int64_t arg[LANES];
    for (int l = 0; l < LANES; l++) best[l] = INFINITY, arg[l] = 0;
    for (int b = 0; b < nb; b += LANES) {
#pragma omp simd
        for (int l = 0; l < LANES; l++)
            relax_col(ci, s->v, s->d, s->pred, i, h, b + l, best, arg, l);
    }
    for (int j = nb; j < n; j++) relax_col(ci, s->v, s->d, s->pred, i, h, j, best, arg, j - nb);
    return (int)arg[lane_pick(best, arg)];
}

/* A free column tied with the nearest unscanned column j, if any (lowest
 * index), else j: ending the path there is what keeps each path O(n) rather
 * than O(n²) on an all-equal matrix. Free columns are never scanned, so their
 * d is current, and the list is short: it shrinks by one per path. */
static int prefer_free(const lap *s, int j)
{
    int best = j;
    if (s->colsol[j] < 0) return j;
    for (int k = 0; k < s->nfree_cols; k++) {
        int jf = s->free_cols[k];
        if (s->d[jf] == s->d[j] && (s->colsol[best] >= 0 || jf < best)) best = jf;
    }
    return best;
}

/* Phase 4: assigns free row f by a shortest augmenting path, then updates v
 * so that every assigned row again sits on a minimum. */
static void augment(lap *s, int f)
{
    int n = s->n, nready = 0;
    for (int j = 0; j < n; j++) s->d[j] = INFINITY;
    int j = prefer_free(s, relax(s, f, 0.0));
    while (s->colsol[j] >= 0) {
        int i = s->colsol[j];
        double h = s->c[(size_t)i * n + j] - s->v[j] - s->d[j];
        s->ready[nready] = j, s->dready[nready] = s->d[j], s->vready[nready] = s->v[j];
        nready++;
        s->d[j] = INFINITY, s->v[j] = -INFINITY; /* parked, see relax_col() */
        j = prefer_free(s, relax(s, i, h));
    }
    double mu = s->d[j];
    for (int k = 0; k < nready; k++) s->v[s->ready[k]] = s->vready[k] + s->dready[k] - mu;
    for (int k = 0; k < s->nfree_cols; k++)
        if (s->free_cols[k] == j) s->free_cols[k] = s->free_cols[--s->nfree_cols];
    for (int i = -1; i != f;) {
        i = (int)s->pred[j];
        s->colsol[j] = i;
        int next = s->rowsol[i];
        s->rowsol[i] = j;
        j = next;
    }
}

static void solve(lap *s)
{
    int n = s->n;
    column_reduction(s, s->ready, s->count);
    reduction_transfer(s, s->count);
    long budget = (long)ARR_BUDGET_PER_ROW * n;
    for (int pass = 0; pass < 2 && s->nfree > 0; pass++) augmenting_row_reduction(s, &budget);
    s->nfree_cols = 0;
    for (int j = 0; j < n; j++)
        if (s->colsol[j] < 0) s->free_cols[s->nfree_cols++] = j;
    for (int k = 0; k < s->nfree; k++) augment(s, s->free_rows[k]);
}

int tcb_lap_solve(const double *cost, int n_rows, int n_cols, int32_t *row_to_col, double *total,
                  tcb_error *err)
{
    int rc = check_costs(cost, n_rows, n_cols, row_to_col, err);
    if (rc) return rc;
    int n = n_rows;
    if (n == 1) {
        row_to_col[0] = 0;
    } else {
        size_t un = (size_t)n;
        double *dbl = malloc(4 * un * sizeof(double));
        int32_t *ints = malloc(5 * un * sizeof(int32_t));
        int64_t *pred = calloc(un, sizeof(int64_t)); /* rows: relax_col's arithmetic stays small */
        if (!dbl || !ints || !pred) {
            free(dbl), free(ints), free(pred);
            return tcb_fail(err, TCB_ERR_NOMEM, "lap: no memory for a %dx%d problem", n, n);
        }
        lap s = {.n = n, .c = cost, .v = dbl, .d = dbl + un, .dready = dbl + 2 * un,
                 .vready = dbl + 3 * un, .rowsol = row_to_col, .colsol = ints,
                 .free_rows = ints + un, .ready = ints + 2 * un, .count = ints + 3 * un,
                 .free_cols = ints + 4 * un, .pred = pred};
        for (int i = 0; i < n; i++) s.rowsol[i] = s.colsol[i] = -1;
        solve(&s);
        free(dbl), free(ints), free(pred);
    }
    if (total) {
        double t = 0.0;
        for (int i = 0; i < n; i++) t += cost[(size_t)i * n + row_to_col[i]];
        *total = t;
    }
    return TCB_OK;
}
