/* `tcbench calibrate` (costs/calibrate.c): measures with costs/step_timing.h
 * every trained method's costs on this machine and writes a calibration
 * file (costs/calibration.h) describing the machine. */
#ifndef TCB_COSTS_CALIBRATE_H
#define TCB_COSTS_CALIBRATE_H

#include <stdio.h>

#include "tcb/error.h"
#include "tcb/sequence.h"

typedef struct tcb_calibrate_opts {
    const int *threads;    /* thread counts to measure, increasing */
    int n_threads;
    const char *method;    /* NULL: every method with train_steps */
    const char *preset;    /* NULL: each of its presets */
    double budget_s;       /* the whole measurement's */
    int quick;             /* fewer steps and pairs: a coarse pass */
    int surface_samples;   /* per mesh, of the reconstruction metrics measured */
    const char *out_path;
    /* A config's (`tcbench calibrate CONFIG`), when methods is not NULL:
     * only the units of its methods (registered names) and the scoring of
     * pairs, measured on `sequence` and written as costs of that sequence;
     * methods NULL: every cost, on the calibration sequence. */
    const char *const *methods;
    int n_methods;
    const tcb_sequence *sequence;
    const char *sequence_name;  /* its "dataset/sequence" */
} tcb_calibrate_opts;
int tcb_calibrate(const tcb_calibrate_opts *o, FILE *out, tcb_error *err);

/* What tcb_calibrate says of --only and --preset before anything is
 * measured (a config's sequence need not be loaded for it). */
int tcb_calibrate_check(const tcb_calibrate_opts *o, tcb_error *err);

#endif
