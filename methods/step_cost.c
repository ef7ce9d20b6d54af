#include "methods/step_cost.h"

#include <stdio.h>

void tcb_step_cost_estimate(const char *method, const char *const *presets, int preset, long long steps,
                            tcb_cost_estimate *out)
{
    out->steps = steps;
    if (preset >= 0) {
        snprintf(out->preset, sizeof out->preset, "%s", presets[preset]);
        return;
    }
    out->fit_s = out->eval_s = -1;
    snprintf(out->basis, sizeof out->basis,
             "%s: a size differs from every preset; calibrate measures the presets only", method);
}
