/* xoshiro256** (Blackman & Vigna): small state, fast, passes BigCrush; the
 * state is explicit so every consumer can own a reproducible stream. */
#include "tcb/rng.h"

#include <math.h>
#include <string.h>

#include "tcb/hash.h"

static uint64_t splitmix64(uint64_t *x)
{
    uint64_t z = (*x += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

static uint64_t rotl(uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }

void tcb_rng_seed(tcb_rng *r, uint64_t seed)
{
    uint64_t x = seed;
    for (int i = 0; i < 4; i++) r->s[i] = splitmix64(&x);
}

void tcb_rng_seed_stream(tcb_rng *r, uint64_t seed, const char *label)
{
    /* FNV-1a of the label, mixed with the seed: distinct labels give
     * unrelated streams for the same seed. */
    uint64_t h = tcb_fnv1a64(TCB_FNV1A64_OFFSET, label, label ? strlen(label) : 0);
    uint64_t x = seed ^ h;
    tcb_rng_seed(r, splitmix64(&x) ^ h);
}

uint64_t tcb_rng_next(tcb_rng *r)
{
    uint64_t *s = r->s;
    uint64_t result = rotl(s[1] * 5, 7) * 9;
    uint64_t t = s[1] << 17;
    s[2] ^= s[0];
    s[3] ^= s[1];
    s[1] ^= s[2];
    s[0] ^= s[3];
    s[2] ^= t;
    s[3] = rotl(s[3], 45);
    return result;
}

double tcb_rng_uniform(tcb_rng *r) { return (double)(tcb_rng_next(r) >> 11) * 0x1.0p-53; }

uint32_t tcb_rng_below(tcb_rng *r, uint32_t n)
{
    /* Lemire's multiply-shift with rejection: unbiased, one division at most. */
    uint64_t m = (uint64_t)(uint32_t)(tcb_rng_next(r) >> 32) * n;
    uint32_t low = (uint32_t)m;
    if (low < n) {
        uint32_t threshold = (uint32_t)(-n) % n;
        while (low < threshold) {
            m = (uint64_t)(uint32_t)(tcb_rng_next(r) >> 32) * n;
            low = (uint32_t)m;
        }
    }
    return (uint32_t)(m >> 32);
}

double tcb_rng_normal(tcb_rng *r)
{
    double u1 = 1.0 - tcb_rng_uniform(r); /* (0, 1] so log is finite */
    double u2 = tcb_rng_uniform(r);
    return sqrt(-2.0 * log(u1)) * cos(2.0 * M_PI * u2);
}

void tcb_rng_permutation(tcb_rng *r, int32_t *perm, int n)
{
    for (int i = 0; i < n; i++) perm[i] = i;
    for (int i = n - 1; i > 0; i--) {
        int j = (int)tcb_rng_below(r, (uint32_t)i + 1);
        int32_t t = perm[i];
        perm[i] = perm[j];
        perm[j] = t;
    }
}
