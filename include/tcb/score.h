/* tcbench — `tcbench score`: correspondences computed anywhere, scored as
 * a cell of a run.
 *
 * The predictions are a directory with one NumPy .npy file per evaluation
 * pair of the sequence's common split, named by the pair's index: 0.npy,
 * 1.npy, … For pair k = (i, j) (the split file's pairs[k]) a file holds,
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
 * params {"pred_dir": <the directory as given>}, message "scored from
 * files", no Chamfer distance (the files hold no reconstructions), fit_s 0.
 * `tcbench report` and `check` read it like any other cell.
 *
 * Everything is checked before anything is written: a missing or surplus
 * file, a wrong shape or dtype, an id out of range, a non-finite point, a
 * file that is no .npy are errors naming the file, and no cell is written.
 * A label the config gives one of its methods is refused (those cells are
 * tcbench run's), and an existing cell is replaced only with `force`. */
#ifndef TCB_SCORE_H
#define TCB_SCORE_H

#include "tcb/config.h"
#include "tcb/error.h"
#include "tcb/metrics.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct tcb_score_opts {
    const char *dataset;   /* a dataset of the config */
    const char *sequence;  /* one of its sequences */
    const char *pred_dir;  /* <k>.npy for each pair k of the split */
    const char *label;     /* the row's name: the cell's "method" */
    int seed;              /* the cell's seed (several prediction sets: several seeds of one row) */
    const char *output;    /* the run directory; NULL: the config's "output" */
    int force;             /* replace an existing cell */
} tcb_score_opts;

/* Scores the directory and writes the cell; its path goes to
 * cell_path[TCB_PATH_MAX] and its summary to *summary (either may be
 * NULL). */
int tcb_score(const tcb_config *cfg, const tcb_score_opts *o, char *cell_path, tcb_summary *summary,
              tcb_error *err);

/* The file readers `tcbench score` and the external method (whose command
 * writes this format) share (harness/score_files.c); errors name the file.
 * read_prediction: one pair's file, on a frame of nv vertices, into
 * pred[nv] (vertex ids; *is_points = 0) or moved[nv][3] (points;
 * *is_points = 1). read_points: surface samples, shape (M, 3) float32 or
 * float64, M >= 1, finite, into *pts (malloc'ed [*n][3], float64 rounded
 * to float32 as above). */
int tcb_score_read_prediction(const char *path, int nv, int32_t *pred, float *moved, int *is_points,
                              tcb_error *err);
int tcb_score_read_points(const char *path, float **pts, int *n, tcb_error *err);

#ifdef __cplusplus
}
#endif
#endif
