/* The vocabulary of the "tcbench-cell/1" file, shared by its writer
 * (store/cell_write.c) and its reader (store/cell_read.c), and the cell as
 * JSON for the bindings (harness/binding.c): the store's face beside
 * tcb/results.h.
 *
 * Metric values may legitimately be non-finite in a diverged cell; JSON has
 * no NaN, so every float metric is written as null when not finite and
 * reads back as NAN (the Chamfer distance of a method without
 * reconstruction is the common case). Strings, counts and seeds are strict. */
#ifndef TCB_STORE_CELL_FORMAT_H
#define TCB_STORE_CELL_FORMAT_H

#include <cjson/cJSON.h>

#include "tcb/results.h"

/* Largest integer a JSON number (a double) holds exactly. */
#define TCB_JSON_INT_MAX 9007199254740992.0

/* The pair columns: the paper's metrics, then the geodesic error's. Cells
 * written before the geodesic error have only the first
 * TCB_N_PAIR_COLUMNS_EUCLIDEAN, and load with no geodesic values. */
#define TCB_N_PAIR_COLUMNS 15
#define TCB_N_PAIR_COLUMNS_EUCLIDEAN 11

extern const char *const tcb_cell_status_names[]; /* indexed by tcb_cell_status; NULL-terminated */
extern const char *const tcb_cell_role_names[];   /* "train", "validation", "test", NULL */
extern const char *const tcb_cell_pair_columns[]; /* [TCB_N_PAIR_COLUMNS], NULL-terminated */

/* A pair's row of the file, v[TCB_N_PAIR_COLUMNS] in tcb_cell_pair_columns
 * order (non-finite values are written as null). */
void tcb_pair_record_row(const tcb_pair_record *r, double *v);

/* The cell as the file's JSON tree (for tcb_cell_save, and for a binding
 * that hands a loaded cell on as text); NULL on failure, with the error
 * naming `path`. */
cJSON *tcb_cell_to_json(const char *path, const tcb_cell_result *c, tcb_error *err);

#endif
