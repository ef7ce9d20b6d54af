/* tcbench — one evaluation pair of a finished (or fitted) cell, looked at
 * closely: `tcbench inspect`.
 *
 * The pair is recomputed exactly as the run computed it (the cell's fitted
 * model from its checkpoint, the pair's random stream, the same projection
 * and metrics), compared with the row in the cell file, and written as
 * files people open in a mesh viewer or load in Python:
 *
 *   source.ply       frame i, vertices coloured by their place on the body
 *                    (x, y, z of the first frame → red, green, blue)
 *   target.ply       frame j in the same colours: what a perfect transfer shows
 *   transfer.ply     frame j, vertex k coloured as the vertex the method
 *                    predicted for it (pred[k]); differences from target.ply
 *                    are the method's errors, drawn where they happen
 *   error.ply        frame j, vertex k coloured by its error |q_pred[k] − q_k|
 *                    (viridis, saturated at the PCK range's end, √0.02)
 *   recon_i.ply,     the method's surface samples of frames i and j (only
 *   recon_j.ply      for methods that reconstruct), each point coloured as
 *                    its nearest GT vertex
 *   vertices.csv     k, pred[k], error[k] and geodesic[k] (the geodesic
 *                    error over sqrt(area), tcb/geodesic.h) for every vertex
 *   pair.json        frames, the target frame's area, the recomputed metrics
 *                    (geodesic ones included), the cell file's row and
 *                    whether they agree, the colour legend
 *
 * Coordinates are the normalized ones the metrics use. Each file is written
 * atomically, and only after everything was computed. */
#ifndef TCB_INSPECT_H
#define TCB_INSPECT_H

#include <stdio.h>

#include "tcb/error.h"
#include "tcb/progress.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct tcb_inspect_opts {
    const char *run_dir;
    const char *method;   /* the config's label */
    int pair;             /* index into the sequence's split */
    int seed;             /* < 0: the config's first seed */
    const char *sequence; /* "dataset/sequence"; NULL when the config has only one */
    const char *out_dir;  /* NULL: <run>/inspect/<dataset>/<sequence>/<method>/seed_<s>/pair_<k> */
    int threads;          /* <= 0: the config's */
    tcb_reporter reporter;
} tcb_inspect_opts;

/* Writes the files above and a short account to `out` (NULL: none). The
 * output directory's path goes to out_path[TCB_PATH_MAX] when non-NULL. */
int tcb_inspect(const tcb_inspect_opts *o, FILE *out, char *out_path, tcb_error *err);

#ifdef __cplusplus
}
#endif
#endif
