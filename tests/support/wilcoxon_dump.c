/* wilcoxon_dump: tcb_wilcoxon on vectors read from stdin, for
 * test_wilcoxon_scipy.sh to compare with scipy.stats.wilcoxon (a test-only
 * program, not installed). Each input line is "n d_1 … d_n"; each output
 * line is "statistic p method n_used" (%.17g, method exact|normal|none). */
#include <stdio.h>
#include <stdlib.h>

#include "tcb/wilcoxon.h"

static const char *method_name[] = {"exact", "normal", "none"};

static int dump_one(int n)
{
    double *d = malloc((size_t)(n > 0 ? n : 1) * sizeof *d);
    if (!d) return 1;
    for (int i = 0; i < n; i++)
        if (scanf("%lf", &d[i]) != 1) {
            fprintf(stderr, "wilcoxon_dump: expected %d numbers\n", n);
            free(d);
            return 2;
        }
    tcb_wilcoxon_result r;
    tcb_error err = {0};
    int rc = tcb_wilcoxon(d, n, &r, &err);
    free(d);
    if (rc != TCB_OK) {
        fprintf(stderr, "wilcoxon_dump: %s\n", err.msg);
        return 2;
    }
    printf("%.17g %.17g %s %d\n", r.statistic, r.p, method_name[r.method], r.n_used);
    return 0;
}

int main(void)
{
    int n;
    while (scanf("%d", &n) == 1) {
        int rc = dump_one(n);
        if (rc) return rc;
    }
    return 0;
}
