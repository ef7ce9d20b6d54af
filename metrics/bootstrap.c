/* Seeded hierarchical paired bootstrap of a mean difference (see
 * tcb/bootstrap.h for the draw order and the quantile rule, which an
 * independent numpy implementation repeats). */
#include "tcb/bootstrap.h"

#include <math.h>
#include <stdlib.h>

#include "tcb/rng.h"

double tcb_quantile_sorted(const double *v, int n, double q)
{
    double h = (double)(n - 1) * q;
    int k = (int)floor(h);
    if (k >= n - 1) return v[n - 1];
    return v[k] + (h - (double)k) * (v[k + 1] - v[k]);
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static int check_finite(const double *x, int seeds, int pairs, char method, tcb_error *err)
{
    for (int s = 0; s < seeds; s++)
        for (int p = 0; p < pairs; p++)
            if (!isfinite(x[(size_t)s * pairs + p]))
                return tcb_fail(err, TCB_ERR_INPUT, "bootstrap: method %c, seed %d, pair %d is not finite",
                                method, s, p);
    return TCB_OK;
}

/* Mean over the drawn seeds of x[seed][p]. */
static double seed_mean(const double *x, const int32_t *seeds, int n_seeds, int pairs, int p)
{
    double sum = 0.0;
    for (int s = 0; s < n_seeds; s++) sum += x[(size_t)seeds[s] * pairs + p];
    return sum / n_seeds;
}

/* One resample: idx holds its S_A + S_B + P draws, made here in that order. */
static double resample(const double *xa, int sa, const double *xb, int sb, int pairs, tcb_rng *rng,
                       int32_t *idx)
{
    for (int k = 0; k < sa; k++) idx[k] = (int32_t)tcb_rng_below(rng, (uint32_t)sa);
    for (int k = 0; k < sb; k++) idx[sa + k] = (int32_t)tcb_rng_below(rng, (uint32_t)sb);
    int32_t *pick = idx + sa + sb;
    for (int k = 0; k < pairs; k++) pick[k] = (int32_t)tcb_rng_below(rng, (uint32_t)pairs);
    double sum = 0.0;
    for (int k = 0; k < pairs; k++)
        sum += seed_mean(xa, idx, sa, pairs, pick[k]) - seed_mean(xb, idx + sa, sb, pairs, pick[k]);
    return sum / pairs;
}

static double full_estimate(const double *xa, int sa, const double *xb, int sb, int pairs, int32_t *all)
{
    int most = sa > sb ? sa : sb;
    for (int s = 0; s < most; s++) all[s] = s;
    double sum = 0.0;
    for (int p = 0; p < pairs; p++)
        sum += seed_mean(xa, all, sa, pairs, p) - seed_mean(xb, all, sb, pairs, p);
    return sum / pairs;
}

int tcb_bootstrap_paired(const double *xa, int sa, const double *xb, int sb, int pairs,
                         uint64_t seed, const char *label, int resamples, int32_t *draws,
                         tcb_boot_result *out, tcb_error *err)
{
    if (sa < 1 || sb < 1 || pairs < 1 || resamples < 0)
        return tcb_fail(err, TCB_ERR_INPUT,
                        "bootstrap: needs at least one seed per method and one pair (seeds %d and %d, "
                        "pairs %d, resamples %d)", sa, sb, pairs, resamples);
    int rc = check_finite(xa, sa, pairs, 'A', err);
    if (!rc) rc = check_finite(xb, sb, pairs, 'B', err);
    if (rc) return rc;
    int r_count = resamples ? resamples : TCB_BOOT_RESAMPLES;
    size_t per = (size_t)sa + (size_t)sb + (size_t)pairs;
    double *v = malloc(sizeof *v * (size_t)r_count);
    int32_t *idx = malloc(sizeof *idx * per);
    if (!v || !idx) {
        free(v);
        free(idx);
        return tcb_fail(err, TCB_ERR_NOMEM, "bootstrap: out of memory for %d resamples", r_count);
    }
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, seed, label);
    for (int r = 0; r < r_count; r++) {
        int32_t *at = draws ? draws + (size_t)r * per : idx;
        v[r] = resample(xa, sa, xb, sb, pairs, &rng, at);
    }
    out->estimate = full_estimate(xa, sa, xb, sb, pairs, idx);
    qsort(v, (size_t)r_count, sizeof *v, cmp_double);
    out->lo = tcb_quantile_sorted(v, r_count, 0.025);
    out->hi = tcb_quantile_sorted(v, r_count, 0.975);
    out->resamples = r_count;
    free(v);
    free(idx);
    return TCB_OK;
}
