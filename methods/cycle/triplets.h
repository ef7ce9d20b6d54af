/* CC (Groueix et al., SGP'19): training-triplet samplers.
 *
 * One CC training sample is a triplet (A, B, C) of frames of one sequence;
 * the cycle losses run A→B→A, A→B→C→A and so on. A batch is B independent
 * triplets. Three ways to pick them:
 *
 *   random     A, B, C independently uniform over all frames (B and C may
 *              equal A or each other; across blocks, as the atlas methods'
 *              random pairs): ShapeNetSeg.__getitem__ with knn=False,
 *              index_2 = np.random.randint(len), index_3 likewise.
 *   knn        A uniform; B and C independently uniform (with replacement)
 *              over the k = min(20, n) nearest frames of A among the n frames
 *              of A's block (tcb/block.h; the whole sequence without blocks),
 *              A itself included and first: ShapeNetSeg.__getitem__ with knn=True,
 *              self.indices[index][np.random.randint(num_neighbors)], where
 *              compute_nearest_neighbors_graph fits sklearn NearestNeighbors
 *              (metric = useful_losses.NN_metric) on the training shapes and
 *              calls kneighbors on the same shapes (so each shape is its own
 *              first neighbour).
 *   neighbors  A uniform; B and C independently uniform over the time window
 *              {f ≠ A : |f − A| ≤ delta} ∩ A's block — the atlas methods'
 *              neighbour pairs (tcb_pair_sample, TCB_PAIRS_NEIGHBORS). Not in
 *              the CC code; tcbench's temporal variant.
 *
 * The knn distance is NN_metric, the symmetric squared Chamfer
 *     D(P, Q) = mean_{p∈P} min_{q∈Q} |p − q|² + mean_{q∈Q} min_{p∈P} |p − q|²
 * (exact nearest neighbours from tcb/nn.h, float squared distances, sums in
 * double), between fixed subsets of the frames' pools: the first
 * min(pool_size, knn_points) pool points (pools are i.i.d. area-uniform
 * samples, so a prefix is a uniform subsample). With knn_in_box (the
 * default) the subsets are first mapped into their frames' CC boxes
 * (augment.h), as the CC code computes the graph on BoundingBox-normalized
 * shapes; without it the sequence's own coordinates are used. The graph is
 * built once at creation: n(n−1)/2 distances per block of n frames, 2 NN
 * passes of m queries over m points each (35 frames × 2500 points: 595
 * pairs). Rows are ordered A first (distance 0), then by (distance, frame
 * index) — ties go to the lower index.
 *
 * Randomness comes only from the caller's tcb_rng (the trainer's stream);
 * one draw uses it in the fixed order A, then B, then C. */
#ifndef TCB_CC_TRIPLETS_H
#define TCB_CC_TRIPLETS_H

#include <stdint.h>

#include "tcb/error.h"
#include "tcb/rng.h"
#include "tcb/sequence.h"

typedef enum tcb_cc_sampling {
    TCB_CC_SAMPLE_RANDOM = 0,   /* "random": CC with knn = 0 */
    TCB_CC_SAMPLE_KNN = 1,      /* "knn": CC with knn = 1, num_neighbors = 20 */
    TCB_CC_SAMPLE_NEIGHBORS = 2 /* "neighbors": time window of A */
} tcb_cc_sampling;

/* "random", "knn", "neighbors"; NULL for a value outside the enum. */
const char *tcb_cc_sampling_name(tcb_cc_sampling s);

/* The inverse of tcb_cc_sampling_name. An unknown (or NULL) name is
 * TCB_ERR_INPUT with the name and the accepted ones in the message. */
int tcb_cc_sampling_parse(const char *name, tcb_cc_sampling *out, tcb_error *err);

#define TCB_CC_KNN_K 20        /* --num_neighbors default */
#define TCB_CC_KNN_POINTS 2500 /* pool points per frame in the knn Chamfer */

typedef struct tcb_cc_sampler_opts {
    tcb_cc_sampling sampling;
    int knn_k;      /* KNN: neighbours per frame before clipping to n_frames, ≥ 1 */
    int knn_points; /* KNN: pool prefix per frame for the Chamfer, ≥ 1 */
    int knn_in_box; /* KNN: 1 = distances between CC-box-normalized subsets (CC), 0 = raw */
    int delta;      /* NEIGHBORS: window half-width, ≥ 1 */
} tcb_cc_sampler_opts;

/* sampling RANDOM, knn_k 20, knn_points 2500, knn_in_box 1, delta 1. */
tcb_cc_sampler_opts tcb_cc_sampler_opts_default(void);

typedef struct tcb_cc_sampler {
    tcb_cc_sampling sampling;
    int n_frames;
    int n_blocks;       /* a copy of the sequence's blocks (0: one block) */
    tcb_block *blocks;
    int delta;          /* NEIGHBORS */
    int k;              /* KNN: min(knn_k, frames of the longest block); 0 otherwise */
    int32_t *knn;       /* KNN: [n_frames][k] frame ids; row a starts with a and holds
                         * min(k, frames of a's block) of them, then −1 */
    double *knn_dist;   /* KNN: [n_frames][k] D(a, knn[a][j]); knn_dist[a][0] = 0 */
} tcb_cc_sampler;

/* A sampler for seq (not kept: the sampler holds no pointer into it).
 * TCB_ERR_INPUT naming the sequence for fewer than 2 frames, bad options,
 * and (KNN) missing pools or a degenerate frame box; TCB_ERR_NOMEM;
 * non-finite pool points are TCB_ERR_INPUT with knn_in_box (the frame box)
 * and TCB_ERR_NUMERIC without (tcb_nn). *out is NULL on error.
 * KNN cost: n(n−1)/2 · 2 · m² squared distances; 35 frames × 2500 points
 * ≈ 2 s of CPU, ≈ 1 s on 2 cores (-O3, rows in parallel). */
int tcb_cc_sampler_create(const tcb_sequence *seq, const tcb_cc_sampler_opts *opts,
                          tcb_cc_sampler **out, tcb_error *err);
void tcb_cc_sampler_free(tcb_cc_sampler *s);

/* out = {A, B, C}. Draws: A = below(n_frames), then B, then C (random:
 * below(n_frames) each; knn: a row position below(k of A's row) each;
 * neighbors: tcb_pair_sample each). */
void tcb_cc_sampler_draw(const tcb_cc_sampler *s, tcb_rng *rng, int out[3]);

/* The symmetric distance matrix D [n_frames][n_frames] (D[a][a] = 0) on
 * the first min(pool_size, points) pool points of each frame, in the CC
 * boxes when in_box; what the knn sampler sorts. Only pairs of frames in one
 * block are measured; D between blocks is +inf. Errors as create. */
int tcb_cc_frame_distances(const tcb_sequence *seq, int points, int in_box, double *D,
                           tcb_error *err);

#endif
