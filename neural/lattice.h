/* A feature lattice sampled trilinearly: one level of the multi-resolution
 * grids of Neu-PiG / PDG (github vc-bonn/pcgrid, src/pcgrid/grid.py).
 *
 * A level is r × r × r nodes spanning the cube [−1, 1]³ corner to corner
 * (node 0 at −1, node r − 1 at +1), F features per node, stored
 * values[(iz·r + iy)·r + ix][F]: x runs fastest, as PyTorch's
 * grid_sample(input [1][F][r][r][r], align_corners=True) reads a point
 * (x, y, z). Points outside the cube take the value at the nearest point
 * of its boundary (padding_mode="border"). A lattice of one node (r = 1:
 * PDG's coarsest level) is that node's value everywhere.
 *
 *   tcb_lattice_forward          out[n][F] += scale · Σ_c w_c(p) · values[c]
 *   tcb_lattice_backward         dvalues[c][F] += scale · Σ_points w_c(p) · dout[p]
 *   tcb_lattice_backward_points  dpts[n][3] += scale · Σ_c ∂w_c/∂p · ⟨values[c], dout[p]⟩
 * The last is for a method that samples at points it moves (PDG's chain
 * samples each field at the positions the previous fields produced); as
 * PyTorch's border padding, a coordinate outside (−1, 1), where the clamp
 * holds it, gets no gradient.
 * Both accumulate, so the levels of a grid add into one output and one
 * gradient (the method averages over levels: scale = 1/levels). The
 * corners and weights of a point depend on r and the point only; the
 * backward's scatter runs over the points in order (deterministic). */
#ifndef TCB_NEURAL_LATTICE_H
#define TCB_NEURAL_LATTICE_H

#include <stdint.h>

/* The 8 corner nodes of p's cell and their trilinear weights (Σ w = 1);
 * r ≥ 1 (r = 1: node 0 weighs 1, the other seven are node 0 weighing 0). */
void tcb_lattice_corners(int r, const float p[3], int32_t node[8], float w[8]);

/* out [n][F] += scale · trilinear sample of values [r³][F] at pts [n][3]. */
void tcb_lattice_forward(float *out, const float *values, int r, int F, const float *pts, int n,
                         float scale);

/* dvalues [r³][F] += scale · adjoint of the sampling applied to dout [n][F]. */
void tcb_lattice_backward(float *dvalues, const float *dout, int r, int F, const float *pts, int n,
                          float scale);

/* dpts [n][3] += scale · the sample's derivative in the points, applied to
 * dout [n][F]. */
void tcb_lattice_backward_points(float *dpts, const float *dout, const float *values, int r, int F,
                                 const float *pts, int n, float scale);

#endif
