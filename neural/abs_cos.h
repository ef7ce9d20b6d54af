/* The normal term pytorch3d's chamfer_distance adds with abs_cosine (and
 * DynoSurf's robust Chamfer copies): 1 − |cos(a, b)| between a moved
 * point's normal a and its neighbour's b,
 *   cos(a, b) = a·b / max(|a||b|, 1e-6)   (F.cosine_similarity, eps 1e-6),
 * with its gradient in a: −sign(cos) (b / (|a||b|) − cos a / |a|²). */
#ifndef TCB_NEURAL_ABS_COS_H
#define TCB_NEURAL_ABS_COS_H

#include <math.h>

#define TCB_ABS_COS_EPS 1e-6

/* 1 − |cos(a, b)|; da += s · ∂/∂a when da is not NULL. */
static inline double tcb_abs_cos_term(const float *a, const float *b, double s, float *da)
{
    double ab = 0, aa = 0, bb = 0;
    for (int d = 0; d < 3; d++) ab += (double)a[d] * b[d], aa += (double)a[d] * a[d], bb += (double)b[d] * b[d];
    double den = sqrt(aa) * sqrt(bb);
    double c = ab / fmax(den, TCB_ABS_COS_EPS), sign = (c > 0) - (c < 0);
    if (da) {
        for (int d = 0; d < 3; d++)
            da[d] -= (float)(s * sign * (den > TCB_ABS_COS_EPS ? b[d] / den - c * a[d] / aa : b[d] / TCB_ABS_COS_EPS));
    }
    return 1 - fabs(c);
}

#endif
