/* Running mean and variance: Welford's update per value, Chan et al.'s
 * pairwise formula to merge two partial results. Both stay accurate where
 * the naive sum / sum-of-squares form cancels catastrophically, and merging
 * lets pairs, cells and seeds be pooled in any grouping. */
#include "tcb/metrics.h"

#include <math.h>

void tcb_stat_push(tcb_stat *s, double x)
{
    s->n += 1.0;
    double delta = x - s->mean;
    s->mean += delta / s->n;
    s->m2 += delta * (x - s->mean);
}

void tcb_stat_merge(tcb_stat *into, const tcb_stat *other)
{
    if (other->n == 0.0) return;
    if (into->n == 0.0) {
        *into = *other;
        return;
    }
    double n = into->n + other->n;
    double delta = other->mean - into->mean;
    into->mean += delta * (other->n / n);
    into->m2 += other->m2 + delta * delta * (into->n * other->n / n);
    into->n = n;
}

/* numpy's std with ddof = 0; NaN for an empty set, as numpy gives. */
double tcb_stat_std(const tcb_stat *s)
{
    return s->n > 0.0 ? sqrt(s->m2 / s->n) : NAN;
}
