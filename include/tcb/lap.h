/* tcbench — exact dense linear assignment (minimum-cost perfect matching).
 *
 * Shortest augmenting paths with dual potentials (the Jonker–Volgenant
 * family, as in Crouse 2016 which scipy.optimize.linear_sum_assignment
 * implements), after JV's warm start: O(n³) worst case, exact for any finite
 * costs, including ties and duplicated rows or columns — exact meaning the
 * optimum of the matrix as given, up to the rounding of reduced costs (a few
 * ulps of the potentials; totals match scipy's to ~1e-15 relative). */
#ifndef TCB_LAP_H
#define TCB_LAP_H

#include <stdint.h>

#include "tcb/error.h"

#ifdef __cplusplus
extern "C" {
#endif

/* cost is [n_rows][n_cols], row-major, owned by the caller (n = 10 000 is
 * 800 MB; the solver adds O(n) scratch). Only square problems with n ≥ 1 are
 * accepted (rectangular or empty → TCB_ERR_INPUT); a NaN/Inf cost, or one
 * beyond ±1e150 (potentials are sums of many costs and must not overflow),
 * → TCB_ERR_INPUT naming the (row, col). On success row_to_col[0..n) is the
 * column assigned to each row (a permutation) and *total (may be NULL) the
 * summed cost, accumulated in double in row order. Minimises; for a maximum
 * pass negated costs. Deterministic: the same matrix gives the same answer. */
int tcb_lap_solve(const double *cost, int n_rows, int n_cols, int32_t *row_to_col, double *total,
                  tcb_error *err);

#ifdef __cplusplus
}
#endif
#endif
