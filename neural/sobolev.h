/* The Sobolev preconditioning of a lattice level ("Large Steps in Inverse
 * Rendering of Geometry", Nicolet, Jacobson, Jakob, SIGGRAPH Asia 2021, as
 * github vc-bonn/pcgrid applies it to grids, src/pcgrid/grid.py): the
 * optimiser works on u = M v, M = I + λ L, where v [r³][F] are the level's
 * values (neural/lattice.h) and L a Laplacian of the lattice's 6-neighbour
 * graph, −1 per neighbour off the diagonal and on it:
 *   TCB_SOBOLEV_PCGRID  twice the neighbour count (2D − A). What pcgrid's
 *                       laplacian_uniform_points builds, and so what
 *                       Neu-PiG and PDG ran: it counts each node's
 *                       occurrences in the edge list, which holds both
 *                       directions of every edge (grid.py, f500176).
 *   TCB_SOBOLEV_GRAPH   the neighbour count (D − A), the graph Laplacian
 *                       of Nicolet et al.
 * A gradient step on u moves v by M⁻¹ times the step: smooth updates,
 * large steps. The values are v = M⁻¹ u, and since M is symmetric the
 * gradient is ∂ℓ/∂u = M⁻¹ ∂ℓ/∂v: one solve each way.
 *
 * The solve is exact here. Either L is the Kronecker sum of three path
 * matrices P (r nodes: tridiagonal, −1 off the diagonal, the diagonal as
 * above with one or two neighbours), and P = Q diag(μ) Qᵀ. So
 *     M⁻¹ = (Q⊗Q⊗Q) diag(1 / (1 + λ (μ_a + μ_b + μ_c))) (Q⊗Q⊗Q)ᵀ,
 * six small transforms along the axes. For D − A, Q is the orthonormal
 * DCT-II basis Q[i][k] = c_k cos(π k (i + ½) / r) (c_0 = √(1/r), else
 * √(2/r)) and μ_k = 2 − 2 cos(π k / r); 2D − A has no closed form, so its
 * Q and μ come from LAPACK's symmetric tridiagonal eigensolver (dstev, in
 * double, once per level). The reference solves M v = u by
 * conjugate gradient instead (warm-started, at most 100 iterations, until
 * ‖r‖² < 1e-4): a documented deviation (docs/protocol.md), tested against
 * CG on the same system in tests/unit/test_sobolev.c. */
#ifndef TCB_NEURAL_SOBOLEV_H
#define TCB_NEURAL_SOBOLEV_H

#include "tcb/error.h"

typedef enum tcb_sobolev_laplacian { TCB_SOBOLEV_PCGRID, TCB_SOBOLEV_GRAPH } tcb_sobolev_laplacian;

/* "pcgrid", "graph" (tcb_sobolev_laplacian order), NULL-terminated: the
 * methods' parameter values. */
extern const char *const tcb_sobolev_laplacian_names[];

typedef struct tcb_sobolev {
    int r;          /* nodes per axis, ≥ 1 */
    double lambda;  /* λ ≥ 0 */
    tcb_sobolev_laplacian laplacian;
    double *Q;      /* [r][r] P's orthonormal eigenvectors, Q[i·r + k] */
    double *gain;   /* [r³] 1 / (1 + λ (μ_a + μ_b + μ_c)), node order of the lattice */
} tcb_sobolev;

int tcb_sobolev_init(tcb_sobolev *s, int r, double lambda, tcb_sobolev_laplacian laplacian, tcb_error *err);
void tcb_sobolev_free(tcb_sobolev *s);

/* v [r³][F] = M⁻¹ u [r³][F]; scratch [r³][F] doubles. v may alias u. The
 * same call gives the gradient: du = M⁻¹ dv. */
void tcb_sobolev_solve(const tcb_sobolev *s, int F, const float *u, float *v, double *scratch);

/* u [r³][F] = M v [r³][F] (sparse, exact): the parameters that give the
 * values v. u may not alias v. */
void tcb_sobolev_apply(const tcb_sobolev *s, int F, const float *v, float *u);

#endif
