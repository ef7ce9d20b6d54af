/* The measured cost of one training step, and the dry-run estimate a
 * training method derives from it (tcb_method_ops.estimate). */
#ifndef TCB_METHODS_STEP_COST_H
#define TCB_METHODS_STEP_COST_H

#include "tcb/method.h"

/* Seconds per step with 1 and with 2 threads, as measured by
 * bench/bench_train_step on `machine`; 0 where not measured. */
typedef struct tcb_step_cost {
    double s1, s2;
    const char *machine;
} tcb_step_cost;

/* fit = steps × the cost for q->n_threads (2 or more use s2: the training
 * step scales no further on the machines we measured), eval = the pairs ×
 * eval_pair_s; `unknown` (NULL when the cost is known) says why not
 * instead. */
void tcb_step_cost_estimate(const tcb_step_cost *c, long long steps, double eval_pair_s,
                            const tcb_cost_query *q, const char *unknown, tcb_cost_estimate *out);

#endif
