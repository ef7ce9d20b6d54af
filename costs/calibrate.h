/* `tcbench calibrate` (costs/calibrate.c): measures with costs/step_timing.h
 * every trained method's costs on this machine and writes a calibration
 * file (costs/calibration.h) describing the machine. */
#ifndef TCB_COSTS_CALIBRATE_H
#define TCB_COSTS_CALIBRATE_H

#include <stdio.h>

#include "tcb/error.h"

typedef struct tcb_calibrate_opts {
    const int *threads;    /* thread counts to measure, increasing */
    int n_threads;
    const char *method;    /* NULL: every method with train_steps */
    const char *preset;    /* NULL: each of its presets */
    double budget_s;       /* the whole measurement's */
    int quick;             /* fewer steps and pairs: a coarse pass */
    int surface_samples;   /* per mesh, of the reconstruction metrics measured */
    const char *out_path;
} tcb_calibrate_opts;
int tcb_calibrate(const tcb_calibrate_opts *o, FILE *out, tcb_error *err);

#endif
