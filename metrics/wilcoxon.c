/* Wilcoxon signed-rank test and Holm's correction (tcb/wilcoxon.h).
 *
 * The rule is scipy 1.10's scipy.stats.wilcoxon with its defaults
 * (scipy/stats/_morestats.py, function wilcoxon; the exact distribution is
 * _get_wilcoxon_distr in scipy/stats/_hypotests.py), so that a tcbench
 * p-value can be checked against scipy number for number:
 *  - method "auto": exact when n ≤ 50, normal approximation otherwise; a
 *    zero difference anywhere switches exact to the approximation (scipy
 *    warns). Ties alone do not: the exact branch then ranks with averaged
 *    ranks and truncates r+ to an integer (scipy's int(r_plus)).
 *  - zero_method "wilcox": zeros are dropped before ranking — but only on the
 *    approximation branch, the only one that can see a zero.
 *  - exact two-sided p: 1 when r+ is the centre ⌊n(n+1)/4⌋ of the
 *    distribution, else 2·min(P(R ≤ r+), P(R ≥ r+)), clipped to 1.
 *  - approximation: z = (T − n(n+1)/4) / σ with
 *    σ² = [n(n+1)(2n+1) − ½ Σ t(t² − 1)] / 24 over tie groups of size t,
 *    no continuity correction; p = 2·sf(|z|) = erfc(|z|/√2).
 *  - T = min(r+, r−) is the statistic in both branches. */
#include "tcb/wilcoxon.h"

#include <math.h>
#include <stdlib.h>

/* Largest n of the exact branch (scipy: len(d) <= 50). */
#define EXACT_MAX_N 50
#define EXACT_MAX_SUM (EXACT_MAX_N * (EXACT_MAX_N + 1) / 2)

typedef struct signed_abs {
    double abs;
    int positive;
} signed_abs;

static int by_abs(const void *a, const void *b)
{
    double x = ((const signed_abs *)a)->abs, y = ((const signed_abs *)b)->abs;
    return (x > y) - (x < y);
}

/* Rank sums of |d| with ties averaged (scipy's rankdata "average"), and the
 * tie term Σ t(t² − 1) of the variance. v is sorted here. */
static void rank_sums(signed_abs *v, int n, double *r_plus, double *r_minus, double *ties)
{
    qsort(v, (size_t)n, sizeof *v, by_abs);
    *r_plus = *r_minus = *ties = 0.0;
    for (int i = 0; i < n;) {
        int j = i + 1;
        while (j < n && v[j].abs == v[i].abs) j++;
        double rank = 0.5 * (double)(i + 1 + j), t = (double)(j - i);
        for (int k = i; k < j; k++) *(v[k].positive ? r_plus : r_minus) += rank;
        *ties += t * (t * t - 1.0);
        i = j;
    }
}

/* Two-sided exact p of r+ under H0 for n ranks 1..n: counts of subsets of
 * {1..n} by sum, built one rank at a time. Counts stay below 2^50 and are
 * exact in double, so the tails are exact sums divided by 2^n. */
double tcb_wilcoxon_smallest_p(int n) { return n <= 1 ? 1.0 : ldexp(1.0, 1 - n); }

static double exact_p(int n, double r_plus)
{
    double count[EXACT_MAX_SUM + 1] = {1.0};
    int total = 0;
    for (int k = 1; k <= n; k++) {
        total += k;
        for (int s = total; s >= k; s--) count[s] += count[s - k];
    }
    int r = (int)r_plus; /* scipy: int(r_plus), a half rank truncated */
    if (r == total / 2) return 1.0;
    double below = 0.0, above = 0.0;
    for (int s = 0; s <= total; s++) {
        if (s <= r) below += count[s];
        if (s >= r) above += count[s];
    }
    double p = 2.0 * ldexp(below < above ? below : above, -n);
    return p > 1.0 ? 1.0 : p;
}

/* Normal approximation without continuity correction, scipy's order of
 * operations kept (mean and variance of r+, both in double). */
static double normal_p(int n, double t, double ties)
{
    double c = (double)n;
    double mean = c * (c + 1.0) * 0.25;
    double var = (c * (c + 1.0) * (2.0 * c + 1.0) - 0.5 * ties) / 24.0;
    double z = (t - mean) / sqrt(var);
    return erfc(fabs(z) / sqrt(2.0));
}

static void no_test(tcb_wilcoxon_result *out, int n_zero)
{
    *out = (tcb_wilcoxon_result){NAN, NAN, 0, n_zero, TCB_WILCOXON_NONE};
}

int tcb_wilcoxon(const double *d, int n, tcb_wilcoxon_result *out, tcb_error *err)
{
    int n_zero = 0;
    for (int i = 0; i < n; i++) {
        if (!isfinite(d[i]))
            return tcb_fail(err, TCB_ERR_INPUT, "wilcoxon: difference %d is not finite (%g)", i, d[i]);
        n_zero += d[i] == 0.0;
    }
    if (n <= 0 || n_zero == n) {
        no_test(out, n_zero);
        return TCB_OK;
    }
    signed_abs *v = malloc((size_t)n * sizeof *v);
    if (!v) return tcb_fail(err, TCB_ERR_NOMEM, "wilcoxon: out of memory for %d differences", n);
    int used = 0;
    for (int i = 0; i < n; i++)
        if (d[i] != 0.0) v[used++] = (signed_abs){fabs(d[i]), d[i] > 0.0};
    double r_plus, r_minus, ties;
    rank_sums(v, used, &r_plus, &r_minus, &ties);
    free(v);
    int exact = n <= EXACT_MAX_N && n_zero == 0;
    double t = r_plus < r_minus ? r_plus : r_minus;
    *out = (tcb_wilcoxon_result){t, exact ? exact_p(used, r_plus) : normal_p(used, t, ties), used,
                                 n_zero, exact ? TCB_WILCOXON_EXACT : TCB_WILCOXON_NORMAL};
    return TCB_OK;
}

typedef struct indexed_p {
    double p;
    int index;
} indexed_p;

/* Ascending p, ties by index, so that equal p-values get the same order on
 * every platform (qsort is not stable). */
static int by_p(const void *a, const void *b)
{
    const indexed_p *x = a, *y = b;
    if (x->p != y->p) return (x->p > y->p) - (x->p < y->p);
    return (x->index > y->index) - (x->index < y->index);
}

int tcb_holm_adjust(const double *p, int m, double *adj, tcb_error *err)
{
    for (int i = 0; i < m; i++)
        if (!(p[i] >= 0.0 && p[i] <= 1.0))
            return tcb_fail(err, TCB_ERR_INPUT, "holm: p-value %d is not in [0, 1] (%g)", i, p[i]);
    if (m <= 0) return TCB_OK;
    indexed_p *s = malloc((size_t)m * sizeof *s);
    if (!s) return tcb_fail(err, TCB_ERR_NOMEM, "holm: out of memory for %d p-values", m);
    for (int i = 0; i < m; i++) s[i] = (indexed_p){p[i], i};
    qsort(s, (size_t)m, sizeof *s, by_p);
    /* The running maximum keeps the adjusted values monotone in p: a test
     * is rejected only if every smaller p before it is. */
    double running = 0.0;
    for (int j = 0; j < m; j++) {
        double a = (double)(m - j) * s[j].p;
        if (a > 1.0) a = 1.0;
        if (a > running) running = a;
        adj[s[j].index] = running;
    }
    free(s);
    return TCB_OK;
}
