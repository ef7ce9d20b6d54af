/* tcbench — flat entry points for bindings in other languages (the Python
 * package python/tcbench calls them through ctypes).
 *
 * A binding that mirrors a C struct byte for byte breaks, silently, the
 * day the struct gains a field (the pair metrics and the cell format grow),
 * so these functions keep every struct on the C side. A binding gets
 *   - metadata as JSON text: a split or a cell exactly as the C reader
 *     understood its file, printed by the C writer (so a number is the
 *     shortest text that reads back to the same double);
 *   - bulk numbers copied into its own buffers: each array is named, its
 *     dtype and shape are in the JSON, and the buffer's size is checked;
 *   - errors in a tcb_error, the one struct it mirrors (tcb_binding_info
 *     gives its size and layout to check the mirror against on load).
 * Every char * returned is malloc'ed: release it with tcb_binding_free
 * (the binding's own free may not be the library's). */
#ifndef TCB_BINDING_H
#define TCB_BINDING_H

#include <stddef.h>
#include <stdint.h>

#include "tcb/error.h"
#include "tcb/sequence.h"

#ifdef __cplusplus
extern "C" {
#endif

/* {"version", "pck_steps", "pair_columns": [the cell files' column names],
 *  "tcb_error": {"size", "msg_offset", "msg_size"}}; NULL when out of
 * memory. */
char *tcb_binding_info(void);
void tcb_binding_free(void *p);

/* One pair's metrics from predicted vertex ids (pred[k] in [0, nv)), by the
 * code that scores a cell's pairs, into
 *   sq[nv], rank[nv]   each vertex's squared error d_k and rank (a fraction);
 *   pck[n_pck]         the pair's PCK curve (n_pck: info's pck_steps);
 *   row[n_row]         the pair's row of a cell file, in the order of info's
 *                      pair_columns (n_row: their count), bit for bit; the
 *                      frames i, j and the Chamfer distance are NaN: a
 *                      prediction alone does not have them.
 * Counts other than the library's are an error (a binding out of date). */
int tcb_binding_pair_metrics(const float *verts_j, int nv, const int32_t *pred, double *sq, double *rank,
                             double *pck, int n_pck, double *row, int n_row, tcb_error *err);

/* The split or cell file at path, validated by the C reader (its errors:
 * tcb_split_load, tcb_cell_load), as the JSON text its C writer prints.
 * NULL on failure. */
char *tcb_binding_split_json(const char *path, tcb_error *err);
char *tcb_binding_cell_json(const char *path, tcb_error *err);

/* The sequence `tcbench run` scores the config's dataset and sequence on
 * (tcb_run_load_sequence), with the config read as the CLI reads it from
 * the current directory; root, when not NULL, replaces the dataset's root
 * as `--root DATASET=DIR` does. NULL on failure; release with
 * tcb_binding_sequence_free. */
tcb_sequence *tcb_binding_sequence_load(const char *config_path, const char *dataset, const char *sequence,
                                        const char *root, tcb_error *err);
void tcb_binding_sequence_free(tcb_sequence *s);
/* {"name", "n_frames", "n_verts", "n_faces", "pool_size", "normalization",
 *  "input_points", "sampling", "blocks": [{"name", "start", "n_frames"}],
 *  "arrays": {NAME: {"dtype": "float32" | "float64" | "int32", "shape": [...]}}}
 * with arrays verts, faces, areas, pools, norm_shift, norm_scale (shape
 * []) and yaw (when aligned); NULL on failure. */
char *tcb_binding_sequence_json(const tcb_sequence *s, tcb_error *err);
/* Copies array `name` into dst, whose size must be the array's in bytes. */
int tcb_binding_sequence_copy(const tcb_sequence *s, const char *name, void *dst, size_t size, tcb_error *err);

/* ---- the evaluator (tcb/score.h): whole splits scored as `tcbench score`
 * scores them, by the same functions. */
typedef struct tcb_binding_evaluator tcb_binding_evaluator;

/* The config read as the CLI reads it (variant and root as --variant and
 * --root DATASET=DIR; NULL: the defaults), the sequence and its split
 * loaded as `tcbench score` loads them. NULL on failure. */
tcb_binding_evaluator *tcb_binding_evaluator_open(const char *config_path, const char *dataset,
                                                  const char *sequence, const char *root, const char *variant,
                                                  tcb_error *err);
void tcb_binding_evaluator_free(tcb_binding_evaluator *e);
/* The loaded sequence, for tcb_binding_sequence_json and _copy; owned by e. */
const tcb_sequence *tcb_binding_evaluator_sequence(const tcb_binding_evaluator *e);
/* {"path": the split file, "run_dir": the config's output, and the split
 * file's fields as tcb_binding_split_json gives them}; NULL on failure. */
char *tcb_binding_evaluator_split_json(const tcb_binding_evaluator *e, tcb_error *err);
/* Scores n arrays, arrays[k] the bytes of a .npy file of len[k] bytes (pair
 * k's prediction, read by the .npy reader the files go through; named
 * "predictions[k]" in messages), or, with n = 0 and path set, the
 * directory or .npz at path. Returns the evaluation as the JSON text of a
 * cell file (tcb_binding_cell_json's; method "" and seed 0); NULL on
 * failure. any_frame: as --any-frame. */
char *tcb_binding_evaluator_score(tcb_binding_evaluator *e, int n, const void *const *arrays, const size_t *len,
                                  const char *path, int any_frame, tcb_error *err);
/* The last evaluation written as the cell <run_dir>/cells/…/<label>/
 * seed_<seed>.json (run_dir NULL: the config's output), as `tcbench score
 * --name label --seed seed [--force]` writes it; returns its path (NULL on
 * failure). */
char *tcb_binding_evaluator_write(tcb_binding_evaluator *e, const char *run_dir, const char *label, int seed,
                                  int force, tcb_error *err);

#ifdef __cplusplus
}
#endif
#endif
