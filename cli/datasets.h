/* The actions of `tcbench datasets` that have files of their own
 * (cli/cmd_datasets.c parses their flags). */
#ifndef TCB_CLI_DATASETS_H
#define TCB_CLI_DATASETS_H

#include <stdint.h>
#include <stdio.h>

#include "tcb/error.h"

/* `tcbench datasets align`: the rotation alignment of an OBJ directory
 * (centred per frame) written as JSON to `out` and, with `plot`, as a PNG
 * of the yaw per frame; both atomically. (cli/datasets_align.c) */
typedef struct tcb_align_cmd {
    const char *out;   /* rotations.json */
    const char *plot;  /* NULL: no plot */
    int samples;       /* points per frame for the Chamfer */
    uint64_t seed;     /* of those samples */
} tcb_align_cmd;
int tcb_datasets_align(const char *dir, const tcb_align_cmd *a, tcb_error *err);

/* `tcbench datasets distortion`: the per-frame non-isometry of a synthetic
 * sequence (generated with seed and n_frames, ≤ 0: its default length) or
 * of an OBJ directory, as a table on out. (cli/datasets_distortion.c) */
int tcb_datasets_distortion(const char *what, uint64_t seed, int n_frames, FILE *out, tcb_error *err);

#endif
