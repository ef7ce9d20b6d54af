#include "neural/adam.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

int tcb_adam_init(tcb_adam *a, size_t n, tcb_error *err)
{
    *a = (tcb_adam){.n = n, .b1 = 0.9, .b2 = 0.999, .eps = 1e-8};
    a->m = calloc(n ? n : 1, sizeof *a->m);
    a->v = calloc(n ? n : 1, sizeof *a->v);
    if (!a->m || !a->v) {
        tcb_adam_free(a);
        return tcb_fail(err, TCB_ERR_NOMEM, "adam: out of memory for its state (%zu params)", n);
    }
    return TCB_OK;
}

void tcb_adam_free(tcb_adam *a)
{
    free(a->m);
    free(a->v);
    a->m = a->v = NULL;
}

void tcb_adam_reset(tcb_adam *a)
{
    memset(a->m, 0, a->n * sizeof *a->m);
    memset(a->v, 0, a->n * sizeof *a->v);
    a->t = 0;
}

void tcb_adam_step_groups(tcb_adam *a, float *params, const float *grads, const size_t *bounds,
                          const double *lrs, int n_groups)
{
    a->t++;
    /* The scalars in double as torch computes them in Python floats. */
    double bc1 = 1.0 - pow(a->b1, (double)a->t), bc2 = 1.0 - pow(a->b2, (double)a->t);
    float sbc2 = (float)sqrt(bc2), eps = (float)a->eps;
    /* 1 − β in double, then rounded, as torch passes `1 - beta` to its kernel:
     * 1.0f − (float)β2 would be off by 4.7e-5 relative. */
    float b1 = (float)a->b1, b2 = (float)a->b2, c1 = (float)(1.0 - a->b1), c2 = (float)(1.0 - a->b2);
    float *m = a->m, *v = a->v;
    for (int g = 0; g < n_groups; g++) {
        float step = (float)(lrs[g] / bc1);
#pragma omp parallel for schedule(static)
        for (size_t k = bounds[g]; k < bounds[g + 1]; k++) {
            float gr = grads[k];
            m[k] = b1 * m[k] + c1 * gr;
            v[k] = b2 * v[k] + c2 * gr * gr;
            params[k] -= step * m[k] / (sqrtf(v[k]) / sbc2 + eps);
        }
    }
}

void tcb_adam_step(tcb_adam *a, float *params, const float *grads, double lr)
{
    const size_t bounds[2] = {0, a->n};
    tcb_adam_step_groups(a, params, grads, bounds, &lr, 1);
}

double tcb_lr_at(double lr0, long long it, long long total)
{
    double lr = lr0;
    if (it >= total * 8 / 10) lr *= 0.1;
    if (it >= total * 9 / 10) lr *= 0.1;
    return lr;
}
