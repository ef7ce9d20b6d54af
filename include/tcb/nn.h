/* tcbench — exact nearest-neighbour search in 3-D.
 *
 * Brute force (SIMD-friendly, exact) below a measured size, FLANN's
 * single kd-tree with unlimited checks (also exact) above it. Squared
 * distances are the float expression (dx² + dy²) + dz² in both backends, so
 * a query's NN distance is bit-identical whichever backend answers it.
 * Brute force breaks exact ties towards the lowest index; the kd-tree breaks
 * them in its own (deterministic) traversal order, so on exact ties only the
 * index may differ. k-NN rows are sorted by (distance, index). */
#ifndef TCB_NN_H
#define TCB_NN_H

#include <stdint.h>

#include "tcb/error.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct tcb_nn tcb_nn;

/* The largest coordinate magnitude the search takes. */
#define TCB_NN_COORD_MAX 1e18f

/* Index over n points (xyz floats, row-major). The points are copied.
 * Coordinates that are not finite or beyond ±1e18 (where squared distances
 * could overflow) are an error (TCB_ERR_NUMERIC), for queries too. */
int tcb_nn_build(const float *pts, int n, tcb_nn **out, tcb_error *err);

/* The same with the search strategy forced (benchmarks and tests); AUTO is
 * what tcb_nn_build uses. Both backends return bit-identical distances. */
typedef enum tcb_nn_backend { TCB_NN_AUTO, TCB_NN_BRUTE, TCB_NN_KDTREE } tcb_nn_backend;
int tcb_nn_build_backend(const float *pts, int n, tcb_nn_backend backend, tcb_nn **out,
                         tcb_error *err);
tcb_nn_backend tcb_nn_backend_of(const tcb_nn *nn); /* BRUTE or KDTREE */
void tcb_nn_free(tcb_nn *nn);
int tcb_nn_size(const tcb_nn *nn);

/* For each of nq queries: idx[q] = nearest point, d2[q] = its squared
 * distance (d2 may be NULL). */
int tcb_nn_query1(const tcb_nn *nn, const float *queries, int nq, int32_t *idx,
                  float *d2, tcb_error *err);

/* k nearest, ascending: idx/d2 are [nq][k]. k ≤ size. */
int tcb_nn_queryk(const tcb_nn *nn, const float *queries, int nq, int k,
                  int32_t *idx, float *d2, tcb_error *err);

/* One-shot convenience: nearest of each query among pts (builds and frees). */
int tcb_nn_nearest(const float *pts, int n, const float *queries, int nq,
                   int32_t *idx, float *d2, tcb_error *err);

#ifdef __cplusplus
}
#endif
#endif
