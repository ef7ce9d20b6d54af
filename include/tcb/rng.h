/* tcbench — seeded random numbers (xoshiro256**, seeded through splitmix64).
 *
 * Every consumer owns its own tcb_rng; there is no global generator. Streams
 * derived from (seed, label) are independent, so adding a new consumer does
 * not shift the numbers any other consumer sees. */
#ifndef TCB_RNG_H
#define TCB_RNG_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct tcb_rng {
    uint64_t s[4];
} tcb_rng;

void tcb_rng_seed(tcb_rng *r, uint64_t seed);

/* Stream for (seed, label), e.g. ("pools", 7) → label "pools/cat_walk". */
void tcb_rng_seed_stream(tcb_rng *r, uint64_t seed, const char *label);

uint64_t tcb_rng_next(tcb_rng *r);

/* Uniform double in [0, 1) with 53 random bits. */
double tcb_rng_uniform(tcb_rng *r);

/* Unbiased integer in [0, n); n > 0. */
uint32_t tcb_rng_below(tcb_rng *r, uint32_t n);

/* Standard normal (Box–Muller, no cached second value: state stays in s[]). */
double tcb_rng_normal(tcb_rng *r);

/* perm[0..n) = a uniformly random permutation of 0..n-1 (Fisher–Yates). */
void tcb_rng_permutation(tcb_rng *r, int32_t *perm, int n);

#ifdef __cplusplus
}
#endif
#endif
