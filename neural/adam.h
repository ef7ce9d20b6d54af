/* Adam over the model's flat parameter vector (reference-protocol §4: β
 * 0.9/0.999, eps 1e-8, no weight decay), with PyTorch's bias correction,
 * and the step lr schedule that TCSR's LRSchedulerFixed and the CC code
 * share (÷10 at 80 % and again at 90 % of the training). */
#ifndef TCB_NEURAL_ADAM_H
#define TCB_NEURAL_ADAM_H

#include <stddef.h>

#include "tcb/error.h"

typedef struct tcb_adam {
    size_t n;
    long long t;       /* updates done */
    double b1, b2, eps;
    float *m, *v;      /* [n] first and second moments */
} tcb_adam;

int tcb_adam_init(tcb_adam *a, size_t n, tcb_error *err);
void tcb_adam_free(tcb_adam *a);

/* Zeroes the moments and the step count: a freshly created optimiser (the CC
 * code recreates Adam at each lr decay). */
void tcb_adam_reset(tcb_adam *a);

/* One update, as torch.optim.Adam: t += 1, m ← β1 m + (1−β1) g,
 * v ← β2 v + (1−β2) g², p ← p − (lr / (1−β1^t)) · m / (√v / √(1−β2^t) + eps). */
void tcb_adam_step(tcb_adam *a, float *params, const float *grads, double lr);

/* The same update with parameter groups: group g is params[bounds[g] ..
 * bounds[g + 1]) with learning rate lrs[g] (as one torch.optim.Adam per
 * group stepping together: one step count). */
void tcb_adam_step_groups(tcb_adam *a, float *params, const float *grads, const size_t *bounds,
                          const double *lrs, int n_groups);

/* The lr of iteration `it` (0-based) of `total`: lr0, ÷10 from iteration
 * ⌊0.8 total⌋, ÷100 from ⌊0.9 total⌋. The scheduler steps at the start of
 * each iteration, so iteration 160,000 of 200,000 already uses lr0/10. */
double tcb_lr_at(double lr0, long long it, long long total);

#endif
