/* A rigid motion per row from a network's 7 outputs (Neu-PiG,
 * github vc-bonn/neu-pig: src/rotation.py "quaternions" and
 * src/optimization.py forward_prediction):
 *   q  = (1 + o₀, o₁, o₂, o₃)                 identity at o = 0
 *   q̂  = q / (‖q‖ + 1e-8)
 *   R  = the rotation of q̂ as PyTorch3D's quaternion_to_matrix computes it
 *        (real part first; s = 2 / (q̂·q̂), R = I + s·(quadratic terms)),
 *        exactly a rotation whatever ‖q̂‖
 *   t  = tanh(0.1 · (o₄, o₅, o₆))
 *   y  = R x + t
 * Rows are [frames][points]: row p moves point x[p mod nx]. The points are
 * fixed (the template), so backward gives the gradient for o only.
 * Computed in double, stored in float. At q = 0 exactly the rotation is
 * undefined (NaN), as in the reference; a training's NaN check ends such a
 * cell as diverged. */
#ifndef TCB_NEURAL_RIGID_H
#define TCB_NEURAL_RIGID_H

#include <stdint.h>

#define TCB_RIGID_OUT 7        /* network outputs per row */
#define TCB_RIGID_EPS 1e-8     /* in the quaternion's normalisation */
#define TCB_RIGID_TSCALE 0.1   /* inside the translation's tanh */

/* y [n][3] from o [n][7] and x [nx][3]. */
void tcb_rigid_forward(float *y, const float *o, const float *x, int64_t n, int nx);

/* do_ [n][7] = ∂ℓ/∂o from dy [n][3] = ∂ℓ/∂y (overwrites). */
void tcb_rigid_backward(float *do_, const float *dy, const float *o, const float *x, int64_t n,
                        int nx);

#endif
