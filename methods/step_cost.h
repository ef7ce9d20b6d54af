/* The dry-run estimate of a trained method whose costs `tcbench calibrate`
 * measures per preset (tcb_method_ops.presets, .train_steps): the harness
 * prices the fit's steps and the evaluation from the calibration. */
#ifndef TCB_METHODS_STEP_COST_H
#define TCB_METHODS_STEP_COST_H

#include "tcb/method.h"

/* A fit of `steps` steps of presets[preset]; preset -1 (a size differs from
 * every preset) is unknown, and basis says why. */
void tcb_step_cost_estimate(const char *method, const char *const *presets, int preset, long long steps,
                            tcb_cost_estimate *out);

#endif
