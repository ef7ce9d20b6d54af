/* tcbench — a sparse symmetric positive definite matrix factored once and
 * solved against many right-hand sides: the Large-Steps systems (I + λL)
 * of a mesh Laplacian that a template's vertices are parametrised by
 * (Nicolet et al. 2021; PDG's template, docs/protocol.md).
 *
 * The factorisation is CHOLMOD's (SuiteSparse, Debian's libsuitesparse-dev):
 * a simplicial LLᵀ after an AMD ordering, in double, on one thread, so the
 * same matrix gives the same bits on every machine. A factor is read-only
 * after tcb_cholesky_factor: solves from several threads may share it.
 *
 * Errors: malformed input (sizes, an index out of range or above the
 * diagonal) is TCB_ERR_INPUT; a value that is not finite, or a matrix that
 * is not positive definite, TCB_ERR_NUMERIC; on failure *out is NULL. */
#ifndef TCB_CHOLESKY_H
#define TCB_CHOLESKY_H

#include "tcb/error.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct tcb_cholesky tcb_cholesky;

/* A (n × n, n ≥ 1) from its lower triangle: n_entries triplets
 * (rows[e], cols[e], vals[e]) with rows[e] ≥ cols[e]; duplicates are
 * summed, absent entries are zero. */
int tcb_cholesky_factor(int n, int n_entries, const int *rows, const int *cols, const double *vals,
                        tcb_cholesky **out, tcb_error *err);

/* b ← A⁻¹ b in place, b row-major [n][k] (k ≥ 1: a mesh's xyz rows, k = 3). */
int tcb_cholesky_solve(const tcb_cholesky *f, double *b, int k, tcb_error *err);

/* The order n of the factored matrix. */
int tcb_cholesky_order(const tcb_cholesky *f);

void tcb_cholesky_free(tcb_cholesky *f);

#ifdef __cplusplus
}
#endif
#endif
