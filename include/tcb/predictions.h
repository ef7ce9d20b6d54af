/* tcbench — reading predictions and the wrong-frame rule: the part of
 * scoring (scoring/) that `tcbench score`, the Python evaluator and a
 * method whose program writes prediction files (the external method) share.
 * The only scoring header a method may include; the file format is
 * tcb/score.h's and docs/formats.md's. */
#ifndef TCB_PREDICTIONS_H
#define TCB_PREDICTIONS_H

#include <stdint.h>

#include "tcb/error.h"
#include "tcb/fsutil.h"
#include "tcb/nn.h"
#include "tcb/npy.h"

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
 * tcb_predictions_close. (scoring/prediction_files.c) */
int tcb_predictions_open(const char *path, int n_pairs, const char *split_path, tcb_predictions *p,
                         tcb_error *err);
void tcb_predictions_close(tcb_predictions *p);

/* The wrong-frame rule for point predictions (docs/formats.md,
 * scoring/frame_rule.c says why and what was measured): shape indexes
 * the vertices of every frame of the sequence; fit is the points' median
 * distance to its nearest vertex, fit_raw the same of the points
 * normalised as the split normalises frame j ((p - shift) / scale, shift
 * its norm_shift[j], scale norm_scale), D the diagonal of frame j's
 * bounding box. The points are refused (raw coordinates) when fit >
 * TCB_FRAME_RAW_RATIO * fit_raw and fit > TCB_FRAME_RAW_MIN * D, and
 * (no points of the shape) when fit > TCB_FRAME_FAR * D.
 * check_frame returns TCB_OK or TCB_ERR_INPUT with a message giving both
 * medians; the caller adds the split's normalisation and the way out. */
#define TCB_FRAME_RAW_RATIO 2.0
#define TCB_FRAME_RAW_MIN 0.01
/* And points whose median distance to the sequence's vertices exceeds
 * TCB_FRAME_FAR box diagonals are refused whatever their frame: they are
 * no points of the shape at all (vertex ids written as x lie hundreds of
 * diagonals away, a unit a thousand times off likewise). A diverged
 * method's points, blown up tenfold, stay within a few: they are scored,
 * as the bad result they are. A method's transfer is held to this clause
 * alone, measured to the box of every frame (scoring/scoring.h,
 * tcb_transfer_check): it is computed on the frames the harness
 * normalised, and the raw clause is no test for it (a barely trained
 * network's points, 1 % of a diagonal off the shape, came 2.4 times
 * closer once normalised a second time on a synthetic sequence, whose
 * normalisation is a small shift). */
#define TCB_FRAME_FAR 100.0
typedef struct tcb_frame_fit {
    double diag;          /* D */
    double fit, fit_raw;  /* median distances to the nearest vertex (INFINITY: beyond the search's range) */
} tcb_frame_fit;
int tcb_frame_fit_measure(const tcb_nn *shape, const float *verts_j, int nv, const float *points, int n,
                          const double shift[3], double scale, tcb_frame_fit *f, tcb_error *err);
int tcb_score_check_frame(const tcb_nn *shape, const float *verts_j, int nv, const float *points, int n,
                          const double shift[3], double scale, tcb_error *err);

/* The readers `tcbench score` and the external method (whose command
 * writes these files) share (scoring/prediction_files.c); errors name the file.
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
