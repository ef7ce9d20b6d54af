/* tcbench — `tcbench score` and the Python evaluator: correspondences
 * computed anywhere, scored as a cell of a run.
 *
 * The predictions hold one NumPy array per evaluation pair of the
 * sequence's common split, named by the pair's index k as a decimal number
 * (no sign, no leading zero): either a directory of .npy files 0.npy,
 * 1.npy, …, or one .npz file whose members are those files (np.savez(path,
 * **{str(k): a_k}) writes them; np.savez's default names arr_0, arr_1, …
 * are refused, saying so), or, from a binding, the arrays in memory. For
 * pair k = (i, j) (the split file's pairs[k]) the array holds,
 * for each of frame i's K GT vertices, either
 *   - the predicted vertex id of frame j: an integer array of shape (K,)
 *     (any of i1 … i8, u1 … u8, either byte order), every id in [0, K); or
 *   - the predicted point on frame j: a float32 or float64 array of shape
 *     (K, 3), finite, projected onto frame j's nearest GT vertex exactly as
 *     a method's transfer is (float64 points are rounded to float32 first,
 *     the precision every method's transfer has).
 * docs/formats.md describes it with a numpy example.
 *
 * The sequence and its split are loaded as `tcbench run` loads them, every
 * pair is scored by the code that scores a method's pairs
 * (tcb_cell_score_pair), and the cell is written to
 * <run>/cells/<dataset>/<sequence>/<label>/seed_<seed>.json in the format
 * of every cell (tcb/results.h): method <label>, method_impl "scored",
 * params {"pred_dir": <the directory as given>} (or {"pred_file": <the
 * .npz>}, or {"pred": "memory"} from a binding), message "scored from
 * files" ("scored from memory"), no Chamfer distance (the files hold no
 * reconstructions), fit_s 0.
 * `tcbench report` and `check` read it like any other cell.
 *
 * Points in the wrong frame are refused (tcb_score_check_frame,
 * tcb/predictions.h): the
 * error says the split's normalisation and how to apply it, and
 * `any_frame` (--any-frame) scores them anyway.
 *
 * Everything is checked before anything is written: a missing or surplus
 * file or member, a wrong shape or dtype, an id out of range, a non-finite
 * point, a file that is no .npy (or .npz) are errors naming the file (and
 * the member), and no cell is written.
 * A label the config gives one of its methods is refused (those cells are
 * tcbench run's), and an existing cell is replaced only with `force`. */
#ifndef TCB_SCORE_H
#define TCB_SCORE_H

#include "tcb/config.h"
#include "tcb/error.h"
#include "tcb/metrics.h"
#include "tcb/predictions.h"
#include "tcb/results.h"

#ifdef __cplusplus
extern "C" {
#endif

/* A (config, dataset, sequence) loaded once for scoring predictions: the
 * sequence and the split as `tcbench run` obtains them (a missing split is
 * drawn and saved as run would), and the last evaluation's cell. The config
 * must outlive it. (harness/score.c) */
typedef struct tcb_evaluator tcb_evaluator;

int tcb_evaluator_open(const tcb_config *cfg, const char *dataset, const char *sequence, tcb_evaluator **ev,
                       tcb_error *err);
void tcb_evaluator_free(tcb_evaluator *ev);
const tcb_sequence *tcb_evaluator_sequence(const tcb_evaluator *ev);
const tcb_split *tcb_evaluator_split(const tcb_evaluator *ev);
const char *tcb_evaluator_split_path(const tcb_evaluator *ev);

/* Every pair of the split read from p and scored (tcb_cell_score_pair, the
 * code that scores a method's cells) into the evaluator's cell, replacing
 * the last one; any_frame: points in the wrong frame are scored too. On
 * error the evaluator has no cell. */
int tcb_evaluator_score(tcb_evaluator *ev, const tcb_predictions *p, int any_frame, tcb_error *err);
/* The last evaluation as a run's cell, in memory (method "" and seed 0
 * until written); NULL before a successful tcb_evaluator_score. */
const tcb_cell_result *tcb_evaluator_cell(const tcb_evaluator *ev);

/* The last evaluation written as <run_dir>/cells/<dataset>/<sequence>/
 * <label>/seed_<seed>.json (tcb/results.h), after the checks of
 * tcb_score_check_cell; its path to cell_path[TCB_PATH_MAX] (may be NULL). */
int tcb_evaluator_write(tcb_evaluator *ev, const char *run_dir, const char *label, int seed, int force,
                        char *cell_path, tcb_error *err);

/* A scored cell's place: label not a method of the config (those cells are
 * tcbench run's) and fitting a cell's method name, and the cell file absent
 * unless force; its path to path[TCB_PATH_MAX]. */
int tcb_score_check_cell(const tcb_config *cfg, const char *run_dir, const char *dataset, const char *sequence,
                         const char *label, int seed, int force, char *path, tcb_error *err);

typedef struct tcb_score_opts {
    const char *dataset;   /* a dataset of the config */
    const char *sequence;  /* one of its sequences */
    const char *pred;      /* a directory of <k>.npy or an .npz of members <k>.npy */
    const char *label;     /* the row's name: the cell's "method" */
    int seed;              /* the cell's seed (several prediction sets: several seeds of one row) */
    const char *output;    /* the run directory; NULL: the config's "output" */
    int force;             /* replace an existing cell */
    int any_frame;         /* score points that lie outside the target frame's extent */
} tcb_score_opts;

/* `tcbench score`: checks what it can without the data, opens the
 * evaluator, scores the predictions and writes the cell; its path goes to
 * cell_path[TCB_PATH_MAX] and its summary to *summary (either may be
 * NULL). */
int tcb_score(const tcb_config *cfg, const tcb_score_opts *o, char *cell_path, tcb_summary *summary,
              tcb_error *err);

#ifdef __cplusplus
}
#endif
#endif
