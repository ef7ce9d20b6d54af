/* The exponential of so(3): a rotation from an axis-angle vector r (the
 * rotation by θ = |r| about r/θ), as DynoSurf's deformer takes its network's
 * outputs (github yaoyx689/DynoSurf @ a2b7324, code/LieAlgebra/so3.py exp
 * and sinc.py):
 *   R = I + a(θ) K + b(θ) K²,  K = [r]× (K v = r × v),
 *   a = sin θ / θ,  b = (1 − cos θ) / θ²,
 * with the Taylor series a = 1 − θ²/6 + θ⁴/120, b = 1/2 − θ²/24 + θ⁴/720
 * below θ = TCB_SO3_TAYLOR (the reference's 0.01), where the closed forms
 * lose their digits.
 *
 * forward:  r [n][3] → R [n][9] (row-major 3×3)
 * backward: dR [n][9] → dr [n][3] (overwrites), through θ as well:
 *   ∂L/∂r_i = a ⟨G, E_i⟩ + b ⟨G, E_i K + K E_i⟩ + r_i (α ⟨G, K⟩ + β ⟨G, K²⟩),
 *   E_i = ∂K/∂r_i, α = a'(θ)/θ, β = b'(θ)/θ (their series below the
 *   threshold: α = −1/3 + θ²/30, β = −1/12 + θ²/180).
 * Computed in double, stored in float. */
#ifndef TCB_NEURAL_SO3_H
#define TCB_NEURAL_SO3_H

#include <stdint.h>

#define TCB_SO3_TAYLOR 0.01

void tcb_so3_exp_forward(float *R, const float *r, int64_t n);
void tcb_so3_exp_backward(float *dr, const float *dR, const float *r, int64_t n);

#endif
