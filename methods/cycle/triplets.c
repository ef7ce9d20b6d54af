/* CC training-triplet samplers; see triplets.h.
 * Followed: ShapeNetSeg.__getitem__ and compute_nearest_neighbors_graph in
 * auxiliary/dataset_shapenet.py, NN_metric in auxiliary/useful_losses.py
 * (ThibaultGROUEIX/CycleConsistentDeformation). */
#include "methods/cycle/triplets.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "methods/cycle/augment.h"
#include "tcb/nn.h"
#include "tcb/split.h"

static const char *const sampling_names[] = {"random", "knn", "neighbors"};
#define N_SAMPLINGS ((int)(sizeof sampling_names / sizeof sampling_names[0]))

const char *tcb_cc_sampling_name(tcb_cc_sampling s)
{
    return (int)s >= 0 && (int)s < N_SAMPLINGS ? sampling_names[s] : NULL;
}

int tcb_cc_sampling_parse(const char *name, tcb_cc_sampling *out, tcb_error *err)
{
    for (int m = 0; m < N_SAMPLINGS; m++)
        if (name && strcmp(name, sampling_names[m]) == 0) {
            *out = (tcb_cc_sampling)m;
            return TCB_OK;
        }
    return tcb_fail(err, TCB_ERR_INPUT,
                    "cc: unknown triplet sampling '%s' (expected random, knn or neighbors)",
                    name ? name : "(null)");
}

tcb_cc_sampler_opts tcb_cc_sampler_opts_default(void)
{
    tcb_cc_sampler_opts o = {.sampling = TCB_CC_SAMPLE_RANDOM,
                             .knn_k = TCB_CC_KNN_K,
                             .knn_points = TCB_CC_KNN_POINTS,
                             .knn_in_box = 1,
                             .delta = 1};
    return o;
}

/* Σ_q min_p |q − p|² over the m queries, in double (the float32
 * torch.sum(dist1) of NN_metric, accumulated more precisely). */
static int nn_sum(const tcb_nn *nn, const float *queries, int m, int32_t *idx, float *d2,
                  double *sum, tcb_error *err)
{
    int rc = tcb_nn_query1(nn, queries, m, idx, d2, err);
    if (rc) return rc;
    double s = 0.0;
    for (int i = 0; i < m; i++) s += d2[i];
    *sum = s;
    return TCB_OK;
}

/* D[a][b] and D[b][a] for all b > a in a's block [.., hi); row a's pairs in
 * one thread. */
static int distance_row(tcb_nn *const *nn, const float *sub, size_t frame_len, int m, int n,
                        int a, int hi, int32_t *idx, float *d2, double *D, tcb_error *err)
{
    D[(size_t)a * n + a] = 0.0;
    for (int b = a + 1; b < hi; b++) {
        double ab, ba;
        int rc = nn_sum(nn[b], sub + (size_t)a * frame_len, m, idx, d2, &ab, err);
        if (!rc) rc = nn_sum(nn[a], sub + (size_t)b * frame_len, m, idx, d2, &ba, err);
        if (rc) return b;
        /* each unordered pair once, so D is exactly symmetric */
        D[(size_t)a * n + b] = D[(size_t)b * n + a] = ab / m + ba / m;
    }
    return -1;
}

int tcb_cc_frame_distances(const tcb_sequence *seq, int points, int in_box, double *D,
                           tcb_error *err)
{
    const int n = seq->n_frames;
    if (n < 2)
        return tcb_fail(err, TCB_ERR_INPUT, "cc: sequence %s has %d frame(s), triplets need 2",
                        seq->name, n);
    if (seq->pool_size < 1 || !seq->pools)
        return tcb_fail(err, TCB_ERR_INPUT, "cc: sequence %s has no point pools", seq->name);
    if (points < 1)
        return tcb_fail(err, TCB_ERR_INPUT, "cc: sequence %s: knn_points = %d, need ≥ 1",
                        seq->name, points);
    const int m = points < seq->pool_size ? points : seq->pool_size;
    const size_t frame_len = (size_t)m * 3;

    int rc = TCB_OK;
    float *sub = malloc((size_t)n * frame_len * sizeof *sub);
    tcb_nn **nn = calloc((size_t)n, sizeof *nn);
    if (!sub || !nn) {
        rc = tcb_fail(err, TCB_ERR_NOMEM, "cc: sequence %s: cannot allocate the knn graph",
                      seq->name);
        goto done;
    }
    for (int f = 0; f < n && !rc; f++) {
        float *s = sub + (size_t)f * frame_len;
        memcpy(s, tcb_seq_pool(seq, f), frame_len * sizeof *s);
        if (in_box) {
            /* CC computes the graph on shapes already BoundingBox-normalized
             * at load (ShapeNetSeg._getitem), from the whole shape. */
            tcb_cc_frame_box box;
            rc = tcb_cc_frame_box_compute(seq, f, &box, err);
            if (rc) break;
            tcb_cc_frame_box_apply(&box, s, m, s);
        }
        rc = tcb_nn_build(s, m, &nn[f], err);
        if (rc) tcb_error_prefix(err, "cc: sequence %s, frame %d: ", seq->name, f);
    }
    if (rc) goto done;
    for (size_t e = 0; e < (size_t)n * n; e++) D[e] = INFINITY; /* between blocks: not measured */

    /* Rows in parallel (each D entry is written by one thread, in a fixed
     * order, so D does not depend on the thread count); tcb_nn's own
     * parallel loop then runs single-threaded inside. Only over brute-force
     * indices (m < 3200, the default 2500 included): a kd-tree search sets
     * FLANN's global log level on every call, and parallelizes itself.
     * 35 frames × 2500 points: ≈ 2 s of CPU, ≈ 1 s on 2 cores (-O3).
     * The coordinates were validated by tcb_nn_build, so the queries cannot
     * fail; the first failing row would be reported all the same. */
    int bad_a = n, bad_b = -1;
    tcb_error row_err = {0};
    const int parallel = tcb_nn_backend_of(nn[0]) == TCB_NN_BRUTE;
#pragma omp parallel if (parallel)
    {
        int32_t *idx = malloc((size_t)m * sizeof *idx);
        float *d2 = malloc((size_t)m * sizeof *d2);
        tcb_error e = {0};
#pragma omp for schedule(dynamic, 1)
        for (int a = 0; a < n - 1; a++) {
            int b = -2, lo, hi;
            tcb_seq_block_of(seq, a, &lo, &hi);
            if (idx && d2) b = distance_row(nn, sub, frame_len, m, n, a, hi, idx, d2, D, &e);
            else tcb_fail(&e, TCB_ERR_NOMEM, "cannot allocate query buffers");
            if (b != -1) {
#pragma omp critical(tcb_cc_distances)
                if (a < bad_a) bad_a = a, bad_b = b, row_err = e;
            }
        }
        free(idx);
        free(d2);
    }
    D[(size_t)(n - 1) * n + (n - 1)] = 0.0;
    if (bad_a < n) {
        if (err) *err = row_err;
        if (bad_b >= 0)
            tcb_error_prefix(err, "cc: sequence %s, frames %d and %d: ", seq->name, bad_a, bad_b);
        else
            tcb_error_prefix(err, "cc: sequence %s: ", seq->name);
        rc = row_err.code ? (int)row_err.code : TCB_ERR_INTERNAL;
    }
done:
    if (nn)
        for (int f = 0; f < n; f++) tcb_nn_free(nn[f]);
    free(nn);
    free(sub);
    return rc;
}

typedef struct {
    double d;
    int32_t f;
} ranked;

static int cmp_ranked(const void *pa, const void *pb)
{
    const ranked *a = pa, *b = pb;
    if (a->d < b->d) return -1;
    if (a->d > b->d) return 1;
    return (a->f > b->f) - (a->f < b->f);
}

/* Row a's length: k clipped to a's block (the whole sequence without blocks). */
static int knn_row_len(const tcb_cc_sampler *s, int a)
{
    int lo, hi;
    tcb_block_find(s->blocks, s->n_blocks, s->n_frames, a, &lo, &hi);
    return s->k < hi - lo ? s->k : hi - lo;
}

/* Row a: a first (kneighbors on the training set returns the query shape
 * itself at distance 0), then the other frames of a's block by (distance,
 * index). */
static int build_knn(tcb_cc_sampler *s, const tcb_sequence *seq, const tcb_cc_sampler_opts *o,
                     tcb_error *err)
{
    const int n = s->n_frames, k = s->k;
    double *D = malloc((size_t)n * n * sizeof *D);
    ranked *row = malloc((size_t)n * sizeof *row);
    s->knn = malloc((size_t)n * k * sizeof *s->knn);
    s->knn_dist = malloc((size_t)n * k * sizeof *s->knn_dist);
    int rc = TCB_OK;
    if (!D || !row || !s->knn || !s->knn_dist)
        rc = tcb_fail(err, TCB_ERR_NOMEM, "cc: sequence %s: cannot allocate the knn graph",
                      seq->name);
    if (!rc) rc = tcb_cc_frame_distances(seq, o->knn_points, o->knn_in_box, D, err);
    for (int a = 0; a < n && !rc; a++) {
        int len = 0, lo, hi, ka = knn_row_len(s, a);
        tcb_seq_block_of(seq, a, &lo, &hi);
        for (int f = lo; f < hi; f++)
            if (f != a) row[len].d = D[(size_t)a * n + f], row[len++].f = f;
        qsort(row, (size_t)len, sizeof *row, cmp_ranked);
        int32_t *out = s->knn + (size_t)a * k;
        double *dist = s->knn_dist + (size_t)a * k;
        out[0] = a, dist[0] = 0.0;
        for (int j = 1; j < k; j++) {
            out[j] = j < ka ? row[j - 1].f : -1;
            dist[j] = j < ka ? row[j - 1].d : INFINITY;
        }
    }
    free(D);
    free(row);
    return rc;
}

/* The sampler keeps no pointer into the sequence: its own copy of the blocks. */
static int copy_blocks(tcb_cc_sampler *s, const tcb_sequence *seq, tcb_error *err)
{
    if (seq->n_blocks == 0) return TCB_OK;
    s->blocks = malloc((size_t)seq->n_blocks * sizeof *s->blocks);
    if (!s->blocks) return tcb_fail(err, TCB_ERR_NOMEM, "cc: cannot allocate a sampler");
    memcpy(s->blocks, seq->blocks, (size_t)seq->n_blocks * sizeof *s->blocks);
    s->n_blocks = seq->n_blocks;
    return TCB_OK;
}

int tcb_cc_sampler_create(const tcb_sequence *seq, const tcb_cc_sampler_opts *opts,
                          tcb_cc_sampler **out, tcb_error *err)
{
    *out = NULL;
    tcb_cc_sampler_opts o = opts ? *opts : tcb_cc_sampler_opts_default();
    if (seq->n_frames < 2)
        return tcb_fail(err, TCB_ERR_INPUT, "cc: sequence %s has %d frame(s), triplets need 2",
                        seq->name, seq->n_frames);
    if (!tcb_cc_sampling_name(o.sampling))
        return tcb_fail(err, TCB_ERR_INPUT, "cc: sequence %s: unknown triplet sampling %d",
                        seq->name, (int)o.sampling);
    if (o.sampling == TCB_CC_SAMPLE_NEIGHBORS && o.delta < 1)
        return tcb_fail(err, TCB_ERR_INPUT,
                        "cc: sequence %s: neighbors sampling needs delta ≥ 1, got %d", seq->name,
                        o.delta);
    if (o.sampling == TCB_CC_SAMPLE_KNN && (o.knn_k < 1 || o.knn_points < 1))
        return tcb_fail(err, TCB_ERR_INPUT,
                        "cc: sequence %s: knn sampling needs k ≥ 1 and points ≥ 1, got %d and %d",
                        seq->name, o.knn_k, o.knn_points);

    tcb_cc_sampler *s = calloc(1, sizeof *s);
    if (!s) return tcb_fail(err, TCB_ERR_NOMEM, "cc: cannot allocate a sampler");
    s->sampling = o.sampling;
    s->n_frames = seq->n_frames;
    s->delta = o.delta;
    int rc = copy_blocks(s, seq, err);
    if (!rc && o.sampling == TCB_CC_SAMPLE_KNN) {
        /* self.num_neighbors = min(self.num_neighbors, len(self.datas)),
         * the datas being those of one block */
        int longest = 0;
        for (int a = 0; a < s->n_frames; a++) {
            int lo, hi;
            tcb_seq_block_of(seq, a, &lo, &hi);
            if (hi - lo > longest) longest = hi - lo;
        }
        s->k = o.knn_k < longest ? o.knn_k : longest;
        rc = build_knn(s, seq, &o, err);
    }
    if (rc) {
        tcb_cc_sampler_free(s);
        return rc;
    }
    *out = s;
    return TCB_OK;
}

void tcb_cc_sampler_free(tcb_cc_sampler *s)
{
    if (!s) return;
    free(s->knn);
    free(s->knn_dist);
    free(s->blocks);
    free(s);
}

void tcb_cc_sampler_draw(const tcb_cc_sampler *s, tcb_rng *rng, int out[3])
{
    const int n = s->n_frames;
    const int a = (int)tcb_rng_below(rng, (uint32_t)n);
    int lo, hi;
    tcb_block_find(s->blocks, s->n_blocks, n, a, &lo, &hi);
    out[0] = a;
    for (int t = 1; t < 3; t++) {
        switch (s->sampling) {
        case TCB_CC_SAMPLE_RANDOM: out[t] = (int)tcb_rng_below(rng, (uint32_t)n); break;
        case TCB_CC_SAMPLE_KNN:
            out[t] = s->knn[(size_t)a * s->k + tcb_rng_below(rng, (uint32_t)knn_row_len(s, a))];
            break;
        case TCB_CC_SAMPLE_NEIGHBORS:
            /* delta ≥ 1 and blocks of ≥ 2 frames were checked: never −1. */
            out[t] = tcb_pair_sample(TCB_PAIRS_NEIGHBORS, s->delta, n, lo, hi, a, rng);
            break;
        }
    }
}
