/* Softplus and its derivatives, element by element, in a form the compiler
 * vectorizes: glibc's expf/log1pf are scalar calls (in ISO C without
 * -ffast-math there is no vector math library), and were 20% of a training
 * step at the CPU scale. Here exp and log1p are branch-free polynomials
 * (max relative error ≈ 2e-7 over the range used, checked against libm in
 * tests/unit/test_atlas_model.c), so a loop over these functions under
 * `omp simd` runs 8 lanes wide.
 *
 * PyTorch's Softplus(beta=1, threshold=20): softplus(s) = s above 20, else
 * log1p(exp(s)); its backward uses σ(s) below the threshold and exactly 1
 * above, so softplus′′ = σ(1 − σ) below and 0 above. */
#ifndef TCB_SOFTPLUS_H
#define TCB_SOFTPLUS_H

#include <math.h>
#include <stdint.h>
#include <string.h>

#define TCB_SOFTPLUS_THRESHOLD 20.0f

/* c ? a : b on the bit patterns. Written as a float ?:, gcc splits the loop
 * body into paths (one of them with a constant to fold) and then, as float
 * arithmetic "may trap" under the default -ftrapping-math, refuses to merge
 * them back: the loop stays scalar. Integer masks keep it one path. */
static inline float tcb_select(int c, float a, float b)
{
    uint32_t ab, bb, mask = (uint32_t)0 - (uint32_t)(c != 0);
    memcpy(&ab, &a, sizeof ab);
    memcpy(&bb, &b, sizeof bb);
    ab = (ab & mask) | (bb & ~mask);
    memcpy(&a, &ab, sizeof a);
    return a;
}

/* exp(x) for x ≤ 0: x = k·ln2 + r with |r| ≤ ln2/2 (Cody–Waite split of
 * ln2), exp(r) by its degree-7 Taylor polynomial (truncation < 6e-9), 2^k
 * by the exponent bits. Below −87 the result is clamped near FLT_MIN
 * instead of going denormal; softplus and σ do not notice 1e-38. The clamp
 * compares bit patterns (monotonic in |x| for negative floats); a NaN is
 * clamped too, softplus keeps it through s. */
static inline float tcb_exp_neg(float x)
{
    const float lo = -87.0f;
    uint32_t xb, lb;
    memcpy(&xb, &x, sizeof xb);
    memcpy(&lb, &lo, sizeof lb);
    memcpy(&x, xb > lb ? &lb : &xb, sizeof x);
    const float shifter = 12582912.0f; /* 1.5·2^23: adding it rounds to an integer */
    float t = x * 1.44269504f + shifter;
    float k = t - shifter;
    /* ln2 = 0.693145752 + 1.42860682e-6: the first part has 16 significant
     * bits, so k times it is exact for |k| ≤ 126 */
    float r = x - k * 0.693145752f;
    r = r - k * 1.42860682e-6f;
    float p = 1.0f / 5040.0f;
    p = p * r + 1.0f / 720.0f;
    p = p * r + 1.0f / 120.0f;
    p = p * r + 1.0f / 24.0f;
    p = p * r + 1.0f / 6.0f;
    p = p * r + 0.5f;
    p = p * r + 1.0f;
    p = p * r + 1.0f;
    int32_t bits = ((int32_t)k + 127) << 23;
    float scale;
    memcpy(&scale, &bits, sizeof scale);
    return p * scale;
}

/* log1p(e) for e in [0, 1] as 2·atanh(t), t = e/(2 + e) ≤ 1/3: an odd series
 * in t, accurate in relative terms down to e → 0 (where log1p(e) ≈ e).
 * Terms to t^19: the first dropped, t^21/21 ≤ 4e-12 · t. */
static inline float tcb_log1p_unit(float e)
{
    float t = e / (2.0f + e), t2 = t * t;
    float p = 1.0f / 19.0f;
    p = p * t2 + 1.0f / 17.0f;
    p = p * t2 + 1.0f / 15.0f;
    p = p * t2 + 1.0f / 13.0f;
    p = p * t2 + 1.0f / 11.0f;
    p = p * t2 + 1.0f / 9.0f;
    p = p * t2 + 1.0f / 7.0f;
    p = p * t2 + 1.0f / 5.0f;
    p = p * t2 + 1.0f / 3.0f;
    p = p * t2 + 1.0f;
    return 2.0f * t * p;
}

/* softplus(s) = max(s, 0) + log1p(exp(−|s|)); *sig = σ(s). */
static inline float tcb_softplus(float s, float *sig)
{
    float e = tcb_exp_neg(-fabsf(s));
    float inv = 1.0f / (1.0f + e), e_inv = e * inv;
    float l = tcb_log1p_unit(e), s_l = s + l;
    float sp = tcb_select(s < 0.0f, l, s_l); /* max(s, 0) + l; NaN stays NaN */
    int above = s > TCB_SOFTPLUS_THRESHOLD;
    *sig = tcb_select(above, 1.0f, tcb_select(s < 0.0f, e_inv, inv));
    return tcb_select(above, s, sp);
}

/* σ(s) = softplus′(s); *curv = softplus′′(s) = σ(1 − σ) = e/(1 + e)² with
 * e = exp(−|s|), which keeps its relative precision where 1 − σ would not. */
static inline float tcb_sigmoid(float s, float *curv)
{
    float e = tcb_exp_neg(-fabsf(s));
    float inv = 1.0f / (1.0f + e), e_inv = e * inv, c = e_inv * inv;
    int above = s > TCB_SOFTPLUS_THRESHOLD;
    *curv = tcb_select(above, 0.0f, c);
    return tcb_select(above, 1.0f, tcb_select(s < 0.0f, e_inv, inv));
}

#endif
