/* Exact nearest neighbours in 3-D: brute force over SoA copies for small
 * point sets, FLANN's single kd-tree (exact with unlimited checks) above.
 *
 * Exactness contract: every squared distance is the float expression
 * (dx*dx + dy*dy) + dz*dz, which is also what FLANN's L2 functor computes for
 * 3-D points. tcbench builds as ISO C11, where gcc does not contract a*b + c
 * into an FMA (-ffp-contract=off), so the scalar, vector and FLANN paths all
 * round identically and the kd-tree's answers are re-scored with the same
 * expression before they are returned. One residual caveat: FLANN
 * accumulates its branch bound in float, so a point whose distance equals
 * the current best to within a few ulps could in principle be pruned; the
 * distances returned would then still agree to those few ulps. */
#include "tcb/nn.h"

#include <flann/flann.h>
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

/* Brute force below this many points, kd-tree at and above it. bench/bench_nn.c
 * (n points, n queries, build included; 2-core AMD EPYC dev machine) gives
 * brute/kd-tree time ratios of
 *     n        1k    2.5k    3k    3.5k   4k    5k    10k   20k
 *     2 thr   0.47  0.68   0.81  0.88  0.96  1.04  1.85  3.47
 *     1 thr   0.66  1.11   1.32  1.49  1.62  1.76  2.81  4.96
 * (brute 0.23 ms at 1k, 20 ms at 10k single-threaded), i.e. the crossover
 * is ≈2.2k points single-threaded and ≈4.7k with two threads (the brute
 * force scales with cores, FLANN's build does not). 3200
 * sits between the two and keeps a shape's 3120–3125 predicted points
 * (reference-protocol §5.3) on one backend. */
#define TCB_NN_BRUTE_MAX 3200

/* Brute-force lanes: 8 floats = one AVX2 register at -march=x86-64-v3. */
#define LANES 8

/* Parallelize a query set only when it is worth a thread team. */
#define PAR_MIN_WORK 65536.0
/* The same for the kd-tree, by query count: FLANN opens a team for every
 * call, so a caller asking one query at a time (tcb_mesh_locate's growing
 * k) paid a team's start and wake-up per query — with two threads and
 * passive waiting, 3x one thread's time (neupig's transfer, calibrate). */
#define PAR_MIN_KD_QUERIES 64

_Static_assert(sizeof(int) == sizeof(int32_t), "FLANN's C API returns int indices");

struct tcb_nn {
    int n;
    tcb_nn_backend backend;
    int npad;           /* BRUTE: n rounded up to LANES */
    float *x, *y, *z;   /* BRUTE: [npad] coordinates, padding = +inf (never nearest) */
    float *pts;         /* KDTREE: [n][3] copy; FLANN's dataset, also used to re-score */
    flann_index_t index;
};

/* Coordinates beyond ±TCB_NN_COORD_MAX could overflow a squared distance
 * (FLT_MAX ≈ 3e38), after which "nearest" means nothing and FLANN would
 * return no neighbour. */
static int check_coords(const float *p, int n, const char *what, tcb_error *err)
{
    for (int i = 0; i < 3 * n; i++)
        if (!(fabsf(p[i]) <= TCB_NN_COORD_MAX)) /* also catches NaN */
            return tcb_fail(err, TCB_ERR_NUMERIC, "nn: %s %d is not finite or beyond ±1e18",
                            what, i / 3);
    return TCB_OK;
}

static inline float dist2(const float *p, const float *q)
{
    float dx = p[0] - q[0], dy = p[1] - q[1], dz = p[2] - q[2];
    return dx * dx + dy * dy + dz * dz;
}

static struct FLANNParameters kdtree_params(int k, int nq)
{
    struct FLANNParameters p = DEFAULT_FLANN_PARAMETERS;
    p.algorithm = FLANN_INDEX_KDTREE_SINGLE;
    p.checks = FLANN_CHECKS_UNLIMITED;
    p.eps = 0.0f;
    p.sorted = 1;
    p.max_neighbors = k;
    p.cores = nq >= PAR_MIN_KD_QUERIES ? omp_get_max_threads() : 1;
    p.log_level = FLANN_LOG_NONE;
    p.random_seed = 0; /* > 0 would reseed the C library's global rand() */
    return p;
}

static int build_brute(tcb_nn *nn, const float *pts, tcb_error *err)
{
    nn->npad = (nn->n + LANES - 1) / LANES * LANES;
    size_t bytes = (size_t)nn->npad * sizeof(float);
    nn->x = malloc(bytes), nn->y = malloc(bytes), nn->z = malloc(bytes);
    if (!nn->x || !nn->y || !nn->z) return tcb_fail(err, TCB_ERR_NOMEM, "nn: out of memory");
    for (int i = 0; i < nn->npad; i++) {
        int in = i < nn->n;
        nn->x[i] = in ? pts[3 * i] : INFINITY;
        nn->y[i] = in ? pts[3 * i + 1] : INFINITY;
        nn->z[i] = in ? pts[3 * i + 2] : INFINITY;
    }
    return TCB_OK;
}

static int build_kdtree(tcb_nn *nn, const float *pts, tcb_error *err)
{
    nn->pts = malloc((size_t)nn->n * 3 * sizeof(float));
    if (!nn->pts) return tcb_fail(err, TCB_ERR_NOMEM, "nn: out of memory");
    memcpy(nn->pts, pts, (size_t)nn->n * 3 * sizeof(float));
    struct FLANNParameters p = kdtree_params(1, 1);
    float speedup = 0.0f;
    nn->index = flann_build_index_float(nn->pts, nn->n, 3, &speedup, &p);
    if (!nn->index) return tcb_fail(err, TCB_ERR_INTERNAL, "nn: FLANN failed to build a kd-tree");
    return TCB_OK;
}

int tcb_nn_build_backend(const float *pts, int n, tcb_nn_backend backend, tcb_nn **out,
                         tcb_error *err)
{
    *out = NULL;
    if (!pts || n < 1) return tcb_fail(err, TCB_ERR_INPUT, "nn: empty point set");
    int rc = check_coords(pts, n, "point", err);
    if (rc) return rc;
    tcb_nn *nn = calloc(1, sizeof *nn);
    if (!nn) return tcb_fail(err, TCB_ERR_NOMEM, "nn: out of memory");
    nn->n = n;
    if (backend == TCB_NN_AUTO) backend = n < TCB_NN_BRUTE_MAX ? TCB_NN_BRUTE : TCB_NN_KDTREE;
    nn->backend = backend;
    rc = backend == TCB_NN_BRUTE ? build_brute(nn, pts, err) : build_kdtree(nn, pts, err);
    if (rc) {
        tcb_nn_free(nn);
        return rc;
    }
    *out = nn;
    return TCB_OK;
}

int tcb_nn_build(const float *pts, int n, tcb_nn **out, tcb_error *err)
{
    return tcb_nn_build_backend(pts, n, TCB_NN_AUTO, out, err);
}

void tcb_nn_free(tcb_nn *nn)
{
    if (!nn) return;
    if (nn->index) {
        struct FLANNParameters p = kdtree_params(1, 1);
        flann_free_index_float(nn->index, &p);
    }
    free(nn->x), free(nn->y), free(nn->z), free(nn->pts);
    free(nn);
}

int tcb_nn_size(const tcb_nn *nn) { return nn->n; }

tcb_nn_backend tcb_nn_backend_of(const tcb_nn *nn) { return nn->backend; }

/* ---- brute force ------------------------------------------------------ */

static inline float soa_d2(const float *restrict x, const float *restrict y,
                           const float *restrict z, int j, float qx, float qy, float qz)
{
    float dx = x[j] - qx, dy = y[j] - qy, dz = z[j] - qz;
    return dx * dx + dy * dy + dz * dz;
}

/* Nearest point to q. Lane l scans indices l, l+LANES, ... in increasing
 * order and keeps only strictly smaller distances, so each lane holds its
 * lowest-index minimum; the final reduction keeps the lowest index among
 * equal lane minima. The fixed-width inner loop vectorizes to AVX2 blends. */
static void brute_nearest(const tcb_nn *nn, const float *q, int32_t *idx, float *d2)
{
    const float *restrict x = nn->x, *restrict y = nn->y, *restrict z = nn->z;
    const float qx = q[0], qy = q[1], qz = q[2];
    float best[LANES];
    int32_t arg[LANES];
    for (int l = 0; l < LANES; l++) best[l] = INFINITY, arg[l] = 0;
    for (int b = 0; b < nn->npad; b += LANES) {
        /* Without `omp simd`, -O3 unrolls the lanes before vectorizing and
         * then fails to vectorize them: 5x slower than -O2. */
#pragma omp simd
        for (int l = 0; l < LANES; l++) {
            float d = soa_d2(x, y, z, b + l, qx, qy, qz);
            int closer = d < best[l];
            /* An arithmetic select: written as ?: gcc turns it into a masked
             * store and keeps arg[] in memory, 2.7x slower. */
            arg[l] += closer * (b + l - arg[l]);
            best[l] = closer ? d : best[l];
        }
    }
    int m = 0;
    for (int l = 1; l < LANES; l++)
        if (best[l] < best[m] || (best[l] == best[m] && arg[l] < arg[m])) m = l;
    *idx = arg[m];
    *d2 = best[m];
}

/* The nearest point of queries [q0, q1). */
static void brute_query1_range(const tcb_nn *nn, const float *queries, int q0, int q1, int32_t *idx, float *d2)
{
    for (int q = q0; q < q1; q++) {
        float d;
        brute_nearest(nn, queries + 3 * (size_t)q, idx + q, &d);
        if (d2) d2[q] = d;
    }
}

/* out[j] = squared distance from q to point j, for all j < npad. */
static void brute_row(const tcb_nn *nn, const float *q, float *restrict out)
{
    const float *restrict x = nn->x, *restrict y = nn->y, *restrict z = nn->z;
    const float qx = q[0], qy = q[1], qz = q[2];
    for (int b = 0; b < nn->npad; b += LANES) {
#pragma omp simd
        for (int l = 0; l < LANES; l++) out[b + l] = soa_d2(x, y, z, b + l, qx, qy, qz);
    }
}

/* Insert (d, j) into the ascending row of length *len ≤ k, after any equal
 * distances: scanning j in increasing order keeps the lowest indices. */
static void row_insert(float *d2, int32_t *idx, int *len, int k, float d, int32_t j)
{
    int p = *len < k ? (*len)++ : k - 1;
    while (p > 0 && d2[p - 1] > d) {
        d2[p] = d2[p - 1];
        idx[p] = idx[p - 1];
        p--;
    }
    d2[p] = d;
    idx[p] = j;
}

static void brute_select(const float *row, int n, int k, int32_t *idx, float *d2)
{
    int len = 0;
    for (int j = 0; j < n; j++)
        if (len < k || row[j] < d2[k - 1]) row_insert(d2, idx, &len, k, row[j], j);
}

/* Queries [q0, q1) into idx (and d2, else scratch [k]), row [npad] the
 * distances' buffer. */
static void brute_queryk_range(const tcb_nn *nn, const float *queries, int q0, int q1, int k, int32_t *idx,
                               float *d2, float *row, float *scratch)
{
    for (int q = q0; q < q1; q++) {
        brute_row(nn, queries + 3 * (size_t)q, row);
        brute_select(row, nn->n, k, idx + (size_t)q * k, d2 ? d2 + (size_t)q * k : scratch);
    }
}

static int brute_queryk(const tcb_nn *nn, const float *queries, int nq, int k, int32_t *idx,
                        float *d2, tcb_error *err)
{
    int failed = 0;
    double work = (double)nq * nn->n;
    if (work <= PAR_MIN_WORK) {
        /* Outside any OpenMP construct and without the heap: a small query
         * (tcb_mesh_locate asks one point at a time) cost 2 to 3 times its
         * search in the construct's entry and the buffers' allocation. */
        float row_buf[TCB_NN_BRUTE_MAX + LANES], scratch_buf[64];
        float *row = nn->npad <= TCB_NN_BRUTE_MAX + LANES ? row_buf : malloc((size_t)nn->npad * sizeof(float));
        float *scratch = d2 || k <= 64 ? scratch_buf : malloc((size_t)k * sizeof(float));
        failed = !row || !scratch;
        if (!failed) brute_queryk_range(nn, queries, 0, nq, k, idx, d2, row, scratch);
        if (row != row_buf) free(row);
        if (scratch != scratch_buf) free(scratch);
        return failed ? tcb_fail(err, TCB_ERR_NOMEM, "nn: out of memory") : TCB_OK;
    }
#pragma omp parallel reduction(| : failed)
    {
        float *row = malloc((size_t)nn->npad * sizeof(float));
        float *scratch = d2 ? NULL : malloc((size_t)k * sizeof(float));
        failed = !row || (!d2 && !scratch);
        int t = omp_get_thread_num(), nt = omp_get_num_threads();
        if (!failed) brute_queryk_range(nn, queries, (int)((long long)nq * t / nt), (int)((long long)nq * (t + 1) / nt), k, idx, d2, row, scratch);
        free(row), free(scratch);
    }
    return failed ? tcb_fail(err, TCB_ERR_NOMEM, "nn: out of memory") : TCB_OK;
}

/* ---- kd-tree ------------------------------------------------------------ */

/* Re-score FLANN's row with our expression and order it by (d2, index);
 * FLANN already returns it sorted by the same distances, so the insertion
 * sort only reorders exact ties. */
static void rescore_row(const tcb_nn *nn, const float *q, int k, int32_t *idx, float *d2)
{
    for (int a = 0; a < k; a++) {
        float d = dist2(nn->pts + 3 * (size_t)idx[a], q);
        int32_t j = idx[a];
        int p = a;
        while (p > 0 && (d2[p - 1] > d || (d2[p - 1] == d && idx[p - 1] > j))) {
            d2[p] = d2[p - 1];
            idx[p] = idx[p - 1];
            p--;
        }
        d2[p] = d;
        idx[p] = j;
    }
}

static int kdtree_queryk(const tcb_nn *nn, const float *queries, int nq, int k, int32_t *idx,
                         float *d2, tcb_error *err)
{
    float *dist = d2 ? d2 : malloc((size_t)nq * k * sizeof(float));
    if (!dist) return tcb_fail(err, TCB_ERR_NOMEM, "nn: out of memory");
    /* The C API takes non-const pointers but does not write the queries. It
     * also sets FLANN's global log level from p on every call; tcbench always
     * passes the same one. */
    struct FLANNParameters p = kdtree_params(k, nq);
    int rc = flann_find_nearest_neighbors_index_float(nn->index, (float *)queries, nq, idx,
                                                       dist, k, &p);
    if (rc != 0) rc = tcb_fail(err, TCB_ERR_INTERNAL, "nn: FLANN search failed");
    for (int q = 0; rc == TCB_OK && q < nq; q++)
        rescore_row(nn, queries + 3 * (size_t)q, k, idx + (size_t)q * k, dist + (size_t)q * k);
    if (!d2) free(dist);
    return rc;
}

/* ---- public queries ----------------------------------------------------- */

int tcb_nn_query1(const tcb_nn *nn, const float *queries, int nq, int32_t *idx, float *d2,
                  tcb_error *err)
{
    if (nq < 0) return tcb_fail(err, TCB_ERR_INPUT, "nn: negative query count %d", nq);
    int rc = check_coords(queries, nq, "query", err);
    if (rc || nq == 0) return rc;
    if (nn->backend == TCB_NN_KDTREE) return kdtree_queryk(nn, queries, nq, 1, idx, d2, err);
    /* a small query outside any OpenMP construct: brute_queryk's reason */
    if ((double)nq * nn->n <= PAR_MIN_WORK) {
        brute_query1_range(nn, queries, 0, nq, idx, d2);
        return TCB_OK;
    }
#pragma omp parallel
    {
        int t = omp_get_thread_num(), nt = omp_get_num_threads();
        brute_query1_range(nn, queries, (int)((long long)nq * t / nt), (int)((long long)nq * (t + 1) / nt), idx, d2);
    }
    return TCB_OK;
}

int tcb_nn_queryk(const tcb_nn *nn, const float *queries, int nq, int k, int32_t *idx,
                  float *d2, tcb_error *err)
{
    if (k < 1 || k > nn->n)
        return tcb_fail(err, TCB_ERR_INPUT, "nn: k = %d outside [1, %d]", k, nn->n);
    if (nq < 0) return tcb_fail(err, TCB_ERR_INPUT, "nn: negative query count %d", nq);
    int rc = check_coords(queries, nq, "query", err);
    if (rc || nq == 0) return rc;
    return nn->backend == TCB_NN_KDTREE ? kdtree_queryk(nn, queries, nq, k, idx, d2, err)
                                        : brute_queryk(nn, queries, nq, k, idx, d2, err);
}

int tcb_nn_nearest(const float *pts, int n, const float *queries, int nq, int32_t *idx,
                   float *d2, tcb_error *err)
{
    tcb_nn *nn;
    int rc = tcb_nn_build(pts, n, &nn, err);
    if (rc) return rc;
    rc = tcb_nn_query1(nn, queries, nq, idx, d2, err);
    tcb_nn_free(nn);
    return rc;
}
