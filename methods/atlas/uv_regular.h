/* The "regular" UV samples of the evaluation (reference-protocol §5.3 item
 * 4, `regular_spacing` as coded): i.i.d. points pushed apart by a parallel
 * random-walk annealing. */
#ifndef TCB_ATLAS_UV_REGULAR_H
#define TCB_ATLAS_UV_REGULAR_H

#include <stdint.h>

#include "tcb/error.h"
#include "tcb/rng.h"

/* uv [m][2] in [0,1]²: x ~ U([0,1]²), step = 0.25/√m, then 250 iterations,
 * each moving ALL points at once: d_i = min_{j≠i} |x_i − x_j|², α_i ~
 * U(0, 2π), c_i = clip(x_i + step (cos α_i, sin α_i), 0, 1), d'_i =
 * min_{j≠i} |c_i − c_j|² among the candidates, x_i ← c_i where d'_i > d_i;
 * step ← 0.994 step. */
int tcb_atlas_uv_regular(int m, tcb_rng *rng, float *uv, tcb_error *err);

/* The evaluation reuses one set per m for all its pairs. The set for m is
 * drawn from the stream (seed, "atlas/uv_regular/<m>"), so it does not
 * depend on which other sizes were asked for first. Owned by the caller,
 * not thread-safe. */
typedef struct tcb_atlas_uv_cache {
    uint64_t seed;
    int n, cap;
    int *m;       /* [n] sizes */
    float **uv;   /* [n] sets, [m[k]][2] each */
} tcb_atlas_uv_cache;

void tcb_atlas_uv_cache_init(tcb_atlas_uv_cache *c, uint64_t seed);
/* *uv = the set of m points, made on the first request; it stays valid
 * until tcb_atlas_uv_cache_free. */
int tcb_atlas_uv_cache_get(tcb_atlas_uv_cache *c, int m, const float **uv, tcb_error *err);
void tcb_atlas_uv_cache_free(tcb_atlas_uv_cache *c);

#endif
