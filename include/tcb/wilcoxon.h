/* tcbench — Wilcoxon signed-rank test on paired differences, and Holm's
 * step-down correction of a family of p-values.
 *
 * tcb_wilcoxon returns what scipy.stats.wilcoxon(d) returns with its
 * defaults (zero_method="wilcox", correction=False, alternative="two-sided",
 * method="auto") in scipy 1.10 — the rule is copied from
 * scipy/stats/_morestats.py, function wilcoxon, and is spelled out in
 * metrics/wilcoxon.c. Agreement to 1e-10 is checked by
 * tests/integration/test_wilcoxon_scipy.sh. */
#ifndef TCB_WILCOXON_H
#define TCB_WILCOXON_H

#include "tcb/error.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum tcb_wilcoxon_method {
    TCB_WILCOXON_EXACT = 0,  /* exact null distribution of r+ (n ≤ 50, no zero) */
    TCB_WILCOXON_NORMAL = 1, /* normal approximation, tie-corrected variance */
    TCB_WILCOXON_NONE = 2    /* no test possible: n = 0 or every difference 0 */
} tcb_wilcoxon_method;

typedef struct tcb_wilcoxon_result {
    double statistic; /* min(r+, r−), ranks of |d| averaged over ties (scipy's T) */
    double p;         /* two-sided p-value in [0, 1]; NaN when method is NONE */
    int n_used;       /* differences ranked: all n (exact) or the nonzero ones (normal) */
    int n_zero;       /* differences exactly 0 */
    tcb_wilcoxon_method method;
} tcb_wilcoxon_result;

/* d[0..n) are the paired differences (caller-owned). A NaN or Inf
 * difference → TCB_ERR_INPUT naming its index. n ≤ 0, or all differences 0,
 * give statistic = p = NaN and method NONE with TCB_OK: scipy returns
 * (nan, nan) for the first and raises ValueError for the second; either
 * way no test was made, and the caller shows it as such. */
int tcb_wilcoxon(const double *d, int n, tcb_wilcoxon_result *out, tcb_error *err);

/* The smallest two-sided p the exact test gives n differences (all of one
 * sign): 2^(1 − n), 1 for n ≤ 1. Below 0.05 only from n = 6 on: fewer
 * differences can never be significant at that level. */
double tcb_wilcoxon_smallest_p(int n);

/* Holm (1979) step-down adjustment of m p-values, in place of a family-wise
 * error rate: with p sorted ascending, adj_(i) = max_{j ≤ i} min(1, (m − j)·p_(j))
 * (j from 0). adj[k] belongs to p[k]; adj may alias p. Equal to R's
 * p.adjust(method = "holm") and statsmodels' multipletests(method="holm").
 * A p outside [0, 1] or NaN → TCB_ERR_INPUT naming its index (leave out
 * tests that were not made before calling). m ≤ 0 is a no-op. */
int tcb_holm_adjust(const double *p, int m, double *adj, tcb_error *err);

#ifdef __cplusplus
}
#endif
#endif
