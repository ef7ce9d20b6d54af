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
 * Points in the wrong frame are refused (tcb_score_check_frame below): the
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
#include "tcb/nn.h"
#include "tcb/npy.h"
#include "tcb/results.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Where a split's predictions come from (a directory, an .npz, memory).
 * read: pair k's array, parsed, into *a (release with tcb_npy_free); name
 * gets how messages name it ("DIR/3.npy", "FILE.npz: 3.npy",
 * "predictions[3]"); its own errors name it already. The cell's params are
 * {key: origin}. */
typedef struct tcb_predictions {
    int (*read)(void *ctx, int k, tcb_npy *a, char name[TCB_PATH_MAX], tcb_error *err);
    void *ctx;
    const char *key, *origin;
    const char *message;   /* the cell's message: "scored from files" */
} tcb_predictions;

/* The directory or .npz file at path as predictions for a split of n_pairs
 * pairs: every pair's file or member present, none beyond (split_path names
 * the split in the messages); nothing is read yet. A path that is a
 * directory is read as one, any other as an .npz. Release with
 * tcb_predictions_close. (harness/score_files.c) */
int tcb_predictions_open(const char *path, int n_pairs, const char *split_path, tcb_predictions *p,
                         tcb_error *err);
void tcb_predictions_close(tcb_predictions *p);

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

/* The wrong-frame rule for point predictions (docs/formats.md,
 * harness/score_frame.c says why and what was measured): shape indexes
 * the vertices of every frame of the sequence; fit is the points' median
 * distance to its nearest vertex, fit_raw the same of the points
 * normalised as the split normalises frame j ((p - shift) / scale, shift
 * its norm_shift[j], scale norm_scale), D the diagonal of frame j's
 * bounding box. The points are refused (raw coordinates) when fit >
 * TCB_FRAME_RAW_RATIO * fit_raw and fit > TCB_FRAME_RAW_MIN * D.
 * check_frame returns TCB_OK or TCB_ERR_INPUT with a message giving both
 * medians; the caller adds the split's normalisation and the way out. */
#define TCB_FRAME_RAW_RATIO 2.0
#define TCB_FRAME_RAW_MIN 0.01
typedef struct tcb_frame_fit {
    double diag;          /* D */
    double fit, fit_raw;  /* median distances to the nearest vertex (INFINITY: beyond the search's range) */
} tcb_frame_fit;
int tcb_frame_fit_measure(const tcb_nn *shape, const float *verts_j, int nv, const float *points, int n,
                          const double shift[3], double scale, tcb_frame_fit *f, tcb_error *err);
int tcb_score_check_frame(const tcb_nn *shape, const float *verts_j, int nv, const float *points, int n,
                          const double shift[3], double scale, tcb_error *err);

/* The readers `tcbench score` and the external method (whose command
 * writes these files) share (harness/score_files.c); errors name the file.
 * read_prediction: one pair's file, on a frame of nv vertices, into
 * pred[nv] (vertex ids; *is_points = 0) or moved[nv][3] (points;
 * *is_points = 1); prediction_of: the same from an array already parsed
 * (its errors name no file). read_points: surface samples, shape (M, 3)
 * float32 or float64, M >= 1, finite, into *pts (malloc'ed [*n][3],
 * float64 rounded to float32 as above). */
int tcb_score_read_prediction(const char *path, int nv, int32_t *pred, float *moved, int *is_points,
                              tcb_error *err);
int tcb_score_prediction_of(const tcb_npy *a, int nv, int32_t *pred, float *moved, int *is_points, tcb_error *err);
int tcb_score_read_points(const char *path, float **pts, int *n, tcb_error *err);

#ifdef __cplusplus
}
#endif
#endif
