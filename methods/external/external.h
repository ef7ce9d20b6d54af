/* Private to methods/external/: the method that runs a user's command
 * (docs/adding-a-method.md, "A method in any language").
 *
 * The protocol, in the cell's work directory W (ctx->work_dir):
 *   fit        tcbench writes W/frames.npy, faces.npy, pools.npy and
 *              manifest.json, then runs `command... fit W/manifest.json`;
 *              the command keeps what it learns in W/model/.
 *   transfer   for the pairs the harness is about to evaluate
 *              (prepare_pairs), tcbench writes W/pairs.npy and the manifest,
 *              empties W/pred/ and runs `command... transfer W/manifest.json`
 *              once; the command writes W/pred/<k>.npy per pair (the format
 *              of `tcbench score`) and, optionally, reconstructions
 *              W/pred/recon_<k>_i.npy and recon_<k>_j.npy. transfer and
 *              reconstruct then hand those files to the harness pair by pair.
 * Output goes to W/external.log; the cell's message quotes its last lines.
 *
 * Why a batch hook rather than a command per pair: a Python (or PyTorch)
 * process costs seconds to start and to load its model, and the evaluation
 * has 500 pairs; with prepare_pairs (method ABI 3) the command starts twice
 * per cell. Why not all the split's pairs in fit: inspect evaluates one
 * pair of a fitted cell, and the harness, not the method, owns the split. */
#ifndef TCB_METHODS_EXTERNAL_H
#define TCB_METHODS_EXTERNAL_H

#include <stddef.h>
#include <stdint.h>

#include "tcb/fsutil.h"
#include "tcb/method.h"

/* The manifest's "protocol": raised when its meaning changes. */
#define EXT_PROTOCOL 1
/* A command's exit status that says its training diverged (NaN/Inf): the
 * cell is recorded as diverged rather than failed. */
#define EXT_EXIT_DIVERGED 3

/* The interpreter of a command whose program is a Python script (its first
 * item ends in ".py"): params.python, else $TCBENCH_PYTHON, else python3
 * from PATH (program.c). A command that names its interpreter itself
 * (["python3", "m.py"]) runs as listed. */
#define EXT_PYTHON_ENV "TCBENCH_PYTHON"
#define EXT_PYTHON_DEFAULT "python3"

/* Names in the work directory. */
#define EXT_MANIFEST "manifest.json"
#define EXT_LOG "external.log"
#define EXT_MODEL_DIR "model"
#define EXT_PRED_DIR "pred"

typedef struct ext_method {
    char **command;       /* params.command, NULL-terminated */
    int n_command;
    char *python;         /* a .py command's interpreter: params.python or $TCBENCH_PYTHON; NULL: the default */
    const char *python_from; /* where python came from ("external.params.python", "TCBENCH_PYTHON"), NULL */
    char program[TCB_PATH_MAX + 64]; /* what the last step ran, for messages: "/usr/bin/python3 [python3 from
                                      * PATH]"; "" before the first */
    double timeout_s;     /* per run of the command; 0: none */
    double grace_s;       /* SIGTERM → SIGKILL when it is stopped */
    int n_frames, n_verts;   /* the fitted sequence's sizes (the checkpoint marker's) */
    char work[TCB_PATH_MAX]; /* the work directory, absolute ("" until fit or prepare_pairs) */
    int exported;         /* this process wrote the sequence's files there */
    /* The batch of prepare_pairs: the split's pairs first .. first + n - 1. */
    int *pairs;           /* [2n] frames */
    int first, n;
    int next;             /* the batch index transfer expects next */
    int has_recon;        /* the command wrote reconstructions */
    int32_t *ids;         /* [n_verts] scratch for predicted ids */
} ext_method;

/* params: {"command": [...], "python": path, "timeout_s": s, "grace_s": s}
 * (params.c); python also from $TCBENCH_PYTHON. */
int ext_params_parse(const char *params_json, ext_method *m, tcb_error *err);
/* params.command as compact JSON (free with cJSON_free; NULL: out of
 * memory): what a fit's checkpoint marker records. */
char *ext_command_json(const ext_method *m);

/* <work>/<name> into out[TCB_PATH_MAX] (export.c). */
int ext_path(const ext_method *m, const char *name, char *out, tcb_error *err);
/* m->work from ctx->work_dir, made absolute, with model/ created. */
int ext_set_work(ext_method *m, const tcb_fit_ctx *ctx, tcb_error *err);
/* frames.npy, faces.npy and (when the sequence has pools) pools.npy. */
int ext_export_sequence(ext_method *m, const tcb_sequence *seq, tcb_error *err);
/* pairs.npy of m's batch: (n, 3) int32 rows (k, i, j). */
int ext_export_pairs(const ext_method *m, tcb_error *err);
/* manifest.json for `step` ("fit" or "transfer": then with the pairs). */
int ext_write_manifest(const ext_method *m, const tcb_sequence *seq, const tcb_fit_ctx *ctx, const char *step,
                       tcb_error *err);

/* program (command[0]) is a Python script: its name ends in ".py" (program.c). */
int ext_is_script(const char *program);
/* The command's argv for a step (program.c): `[interpreter] command... step
 * manifest`, NULL-terminated, in *argv (free the array, not its strings);
 * the interpreter first when command[0] is a .py script. */
int ext_step_argv(const ext_method *m, const char *step, const char *manifest, char ***argv, tcb_error *err);
/* argv[0]'s executable into path[TCB_PATH_MAX], absolute (process.h's
 * ext_proc_resolve), and m->program set to say it and where it came from;
 * an error naming the params key or variable that gave it when there is
 * none. */
int ext_resolve_program(ext_method *m, char *const *argv, char *path, tcb_error *err);
/* A failure of the method after its command ran: rc, with err's message
 * naming the program that ran ("; program: ..."); TCB_OK, interrupts and
 * TCB_ERR_UNSUPPORTED (no reconstructions) pass unchanged. */
int ext_name_program(const ext_method *m, int rc, tcb_error *err);

/* Runs `command... step <work>/manifest.json` (step.c): TCB_OK when it
 * exits 0; otherwise an error saying how it ended, naming the program that
 * ran, with its last lines; TCB_ERR_INTERRUPTED on a stop request,
 * TCB_ERR_NUMERIC on EXT_EXIT_DIVERGED. The log's header names the
 * program too. */
int ext_run_step(ext_method *m, const char *step, const tcb_fit_ctx *ctx, tcb_error *err);

/* After the transfer step (outputs.c): every pred/<k>.npy of the batch
 * exists, and reconstructions for every pair or for none (sets has_recon). */
int ext_check_outputs(ext_method *m, tcb_error *err);
/* Batch pair b's prediction as points on frame j, out[n_verts][3]. */
int ext_read_transfer(ext_method *m, const tcb_sequence *seq, int b, float *out, tcb_error *err);
/* Batch pair b's reconstruction of frame i (which = 'i') or j ('j'). */
int ext_read_recon(const ext_method *m, int b, char which, float **pts, int *n, tcb_error *err);

/* The last lines (at most max_lines) the log got after byte `from`,
 * joined by " | ", printable ASCII, in out[size]: the latest lines when
 * not all fit; "" when there are none (log_tail.c). */
void ext_log_tail(const char *path, long from, int max_lines, char *out, size_t size);

#endif
