/* tcbench — exact dense linear assignment (minimum-cost perfect matching).
 *
 * Shortest augmenting paths with dual potentials (the Jonker–Volgenant
 * family, as in Crouse 2016 which scipy.optimize.linear_sum_assignment
 * implements): O(n³) worst case, exact for any finite costs, including ties
 * and duplicated rows or columns. */
#ifndef TCB_LAP_H
#define TCB_LAP_H

#include <stdint.h>

#include "tcb/error.h"

#ifdef __cplusplus
extern "C" {
#endif

/* cost is [n_rows][n_cols], row-major. Only square problems are accepted
 * (rectangular → TCB_ERR_INPUT); any NaN/Inf cost → TCB_ERR_INPUT naming the
 * entry. On success row_to_col[r] is the column assigned to row r (a
 * permutation) and *total (may be NULL) the summed cost, accumulated in
 * double. */
int tcb_lap_solve(const double *cost, int n_rows, int n_cols, int32_t *row_to_col, double *total,
                  tcb_error *err);

#ifdef __cplusplus
}
#endif
#endif
