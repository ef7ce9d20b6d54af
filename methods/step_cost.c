#include "methods/step_cost.h"

#include <stdio.h>

void tcb_step_cost_estimate(const tcb_step_cost *c, long long steps, double eval_pair_s,
                            const tcb_cost_query *q, const char *unknown, tcb_cost_estimate *out)
{
    int two = q->n_threads >= 2;
    double step = c ? (two ? c->s2 : c->s1) : 0;
    if (unknown || step <= 0) {
        out->fit_s = out->eval_s = -1;
        snprintf(out->basis, sizeof out->basis, "%s",
                 unknown ? unknown : "no step cost measured for this thread count");
        return;
    }
    out->fit_s = (double)steps * step;
    out->eval_s = q->n_pairs * eval_pair_s;
    snprintf(out->basis, sizeof out->basis, "%lld steps x %.1f ms (%d thread%s, %s)", steps, step * 1e3,
             two ? 2 : 1, two ? "s" : "", c->machine);
}
