/* Private to harness/: pieces shared by the config reader, the runner and
 * the CLI. Not installed, not part of the method ABI. */
#ifndef TCB_HARNESS_INTERNAL_H
#define TCB_HARNESS_INTERNAL_H

#include <stddef.h>

#include "tcb/config.h"
#include "tcb/method.h"
#include "tcb/results.h"
#include "tcb/sequence.h"
#include "tcb/split.h"

/* Value names of the config's enums, NULL-terminated; indexed by the enum. */
extern const char *const tcb_config_source_names[];   /* tcb_source */
extern const char *const tcb_config_norm_names[];     /* tcb_normalization */
extern const char *const tcb_config_sampling_names[]; /* with_replacement: 0, 1 */

/* The config with every default filled in, pretty-printed; malloc'ed, NULL
 * when out of memory. (harness/config_dump.c) */
char *tcb_config_normalized_json(const tcb_config *c);

/* Short git revision of the source tree tcbench was built from, or
 * "unknown". (harness/sysinfo.c) */
void tcb_git_revision(char *out, size_t size);
/* Peak resident set size of this process so far, in KiB. */
long tcb_peak_rss_kb(void);

/* "synth/quadruped_walk/nearest/seed 0": how progress and logs name a cell.
 * The size fits the longest dataset, sequence and method names. */
#define TCB_CELL_LABEL_MAX 320
void tcb_cell_label(char *out, size_t size, const char *dataset, const char *sequence,
                    const char *method, int seed);

/* Everything one cell needs besides the method: the loaded sequence, its
 * split and where its files go. */
typedef struct tcb_cell_job {
    const tcb_sequence *seq;
    const tcb_split *split;
    const char *split_path;
    const tcb_dataset_spec *dataset;
    const tcb_method_spec *method;
    const tcb_method_ops *ops;
    int seed;
    int threads;
    int reuse_checkpoint;     /* load `checkpoint` when present instead of fitting */
    const char *work_dir;     /* created by the caller */
    const char *checkpoint;   /* <work_dir>/model.ckpt, written after fit when ops->save */
    const char *git_revision;
    double load_s;            /* time spent loading the sequence */
    tcb_reporter reporter;
} tcb_cell_job;

/* Runs one cell into *out (status ok, failed or diverged). A method's error
 * is recorded in the cell, not returned: the return value is non-zero only
 * for harness failures (out of memory, metrics given bad input). Free *out
 * with tcb_cell_free. (harness/cell.c) */
int tcb_cell_run(const tcb_cell_job *job, tcb_cell_result *out, tcb_error *err);

#endif
