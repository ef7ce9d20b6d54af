/* Private to harness/: the vocabulary of the "tcbench-cell/1" file, shared
 * by its writer (results.c) and its reader (results_load.c).
 *
 * Metric values may legitimately be non-finite in a diverged cell; JSON has
 * no NaN, so every float metric is written as null when not finite and
 * reads back as NAN (the Chamfer distance of a method without
 * reconstruction is the common case). Strings, counts and seeds are strict. */
#ifndef TCB_HARNESS_RESULTS_FORMAT_H
#define TCB_HARNESS_RESULTS_FORMAT_H

/* Largest integer a JSON number (a double) holds exactly. */
#define TCB_JSON_INT_MAX 9007199254740992.0

#define TCB_N_PAIR_COLUMNS 11

extern const char *const tcb_cell_status_names[]; /* indexed by tcb_cell_status; NULL-terminated */
extern const char *const tcb_cell_role_names[];   /* "train", "validation", "test", NULL */
extern const char *const tcb_cell_pair_columns[]; /* [TCB_N_PAIR_COLUMNS], NULL-terminated */

#endif
