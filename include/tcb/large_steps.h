/* tcbench — the Large-Steps parametrisation of a mesh's vertices ("Large
 * Steps in Inverse Rendering of Geometry", Nicolet, Jacobson & Jakob,
 * SIGGRAPH Asia 2021): an optimiser works on u = M v instead of the
 * vertices v [nv][3], with M = I + λL and L the uniform Laplacian of the
 * mesh's edge graph (each vertex's neighbour count on the diagonal, −1 per
 * edge: D − A). A gradient step on u moves v by M⁻¹ times the step, a
 * smooth update. The vertices are v = M⁻¹ u, and since M is symmetric the
 * gradient is ∂ℓ/∂u = M⁻¹ ∂ℓ/∂v: one solve each way (PDG's evolving
 * template, λ = 16; docs/protocol.md).
 *
 * M is factored once by CHOLMOD (tcb/cholesky.h), in double; the arrays
 * are float [nv][3] like every mesh's. */
#ifndef TCB_LARGE_STEPS_H
#define TCB_LARGE_STEPS_H

#include <stdint.h>

#include "tcb/cholesky.h"
#include "tcb/error.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct tcb_large_steps {
    int nv, ne;
    double lambda;
    int32_t *edges;          /* [ne][2] the mesh's undirected edges, each once */
    tcb_cholesky *factor;    /* of M */
} tcb_large_steps;

/* M of the mesh with nv vertices and faces [nf][3], λ ≥ 0. */
int tcb_large_steps_init(tcb_large_steps *ls, int nv, const int32_t *faces, int nf, double lambda,
                         tcb_error *err);
void tcb_large_steps_free(tcb_large_steps *ls);

/* u [nv][3] = M v [nv][3] (exact, sparse; u may not alias v). */
void tcb_large_steps_apply(const tcb_large_steps *ls, const float *v, float *u);

/* x [nv][3] = M⁻¹ b [nv][3]: the vertices of parameters u, or the
 * parameters' gradient of a vertex gradient (x may alias b). */
int tcb_large_steps_solve(const tcb_large_steps *ls, const float *b, float *x, tcb_error *err);

#ifdef __cplusplus
}
#endif
#endif
