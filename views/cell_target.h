/* A cell of a finished run, picked by name and reopened with its fitted
 * model, for `tcbench inspect` and `tcbench frames` (views/cell_target.c). */
#ifndef TCB_VIEWS_CELL_TARGET_H
#define TCB_VIEWS_CELL_TARGET_H

#include "harness/harness.h"

/* A cell of a finished run picked by name. */
typedef struct tcb_cell_target {
    const tcb_dataset_spec *d;
    const tcb_sequence_spec *s;
    const tcb_method_spec *m;
    const tcb_method_ops *ops;
    int seed;
} tcb_cell_target;

/* <run_dir>/config.json loaded with its plug-ins; an error names the file
 * ("... is not a run directory" when there is none). */
int tcb_run_config_open(const char *run_dir, tcb_config *cfg, tcb_error *err);
/* The cell of method label `method`, seed (< 0: the method's first) and
 * sequence "dataset/sequence" (NULL: the config's only one); every name the
 * config lacks is an error saying what it has. */
int tcb_cell_target_resolve(const tcb_config *cfg, const char *method, int seed, const char *sequence,
                            tcb_cell_target *t, tcb_error *err);

/* The target's sequence, split and paths, and a job that reopens its
 * fitted model (reuse and require the checkpoint: never refit a model that
 * saves). threads <= 0: the config's. */
typedef struct tcb_cell_session {
    tcb_sequence seq;
    tcb_split split;
    char split_path[TCB_PATH_MAX], work[TCB_PATH_MAX], ckpt[TCB_PATH_MAX];
    tcb_cell_job job;
} tcb_cell_session;
int tcb_cell_session_open(const tcb_config *cfg, const char *run_dir, const tcb_cell_target *t,
                          int threads, tcb_reporter reporter, tcb_cell_session *s, tcb_error *err);
void tcb_cell_session_close(tcb_cell_session *s);

#endif
