/* The two-way Chamfer in the L1 metric with its normal term: pytorch3d's
 * chamfer_distance(x, y, x_normals, y_normals, norm=1) with its defaults
 * (pytorch3d/loss/chamfer.py, v0.7.4: means over points, abs_cosine), as
 * DynoSurf's stage 1 fits its template to the keyframe (github
 * yaoyx689/DynoSurf @ a2b7324, code/loss.py L29-47). For samples X [nx][3]
 * with normals NX, and data Y [ny][3] with normals NY:
 *
 *   i → j(i)  the nearest y to x_i in the L1 metric (and j → i(j) back)
 *   cham   = mean_i |x_i − y_j(i)|₁ + mean_j |y_j − x_i(j)|₁
 *   normal = mean_i (1 − |cos(nx_i, ny_j(i))|) + mean_j (1 − |cos(ny_j, nx_i(j))|)
 *   cos(a, b) = a·b / max(|a||b|, 1e-6)   (neural/abs_cos.h)
 *
 * The gradient goes to X and NX (Y is data): ∂|d|₁/∂d = sign(d) (0 at 0,
 * as torch's abs). The nearest neighbours are exact: the L1-nearest point
 * is among the L2-nearest within its L1 distance (|d|₂ ≤ |d|₁), so the
 * search takes 16 L2 neighbours from tcb_nn and falls back to every point
 * when the 16th is not beyond the best L1 distance found. */
#ifndef TCB_NEURAL_CHAMFER_L1_H
#define TCB_NEURAL_CHAMFER_L1_H

#include <stdint.h>

#include "tcb/error.h"
#include "tcb/nn.h"

#define TCB_CHAMFER_L1_CANDIDATES 16

/* For each query, idx = its L1-nearest of pts (tcb_nn index over them;
 * ties to the lowest index) and d1 = that distance (may be NULL). */
int tcb_nearest_l1(const tcb_nn *index, const float *pts, int n, const float *queries, int nq, int32_t *idx,
                   float *d1, tcb_error *err);

/* *cham and *normal as above; dX and dNX [nx][3] = their gradients
 * (overwritten; dNX may be NULL, and NX/NY may be NULL when it is, giving
 * *normal = 0). y_index indexes Y; X's index is built inside. */
int tcb_chamfer_l1(const float *X, const float *NX, int nx, const float *Y, const float *NY, int ny,
                   const tcb_nn *y_index, double *cham, double *normal, float *dX, float *dNX, tcb_error *err);

#endif
