/* Non-rigid registration ν_X(Y) of a point set with normals onto another:
 * a re-implementation of Thea's `Register` tool (S. Chaudhuri; version of
 * 2021-03, no labels, no salient points), as reference-protocol §6.2
 * describes it step by step. Pure: no I/O, no global state, deterministic. */
#ifndef TCB_NRICP_REGISTER_H
#define TCB_NRICP_REGISTER_H

#include "tcb/error.h"

typedef struct nricp_params {
    int rounds;      /* ICP rounds (Thea --rounds; TCSR passes 25) */
    int smooth;      /* smoothing iterations in every round but the last (--smooth 3) */
    int smooth_last; /* smoothing iterations in the last round (--smooth-last 1) */
    int k;           /* neighbours per point in the smoothing graphs, self included (8) */
} nricp_params;

/* The settings of the TCSR call. */
static inline nricp_params nricp_default_params(void) { return (nricp_params){25, 3, 1, 8}; }

/* Deforms the source cloud (src, src_nrm: [n_src][3]) onto the target cloud
 * (dst, dst_nrm: [n_dst][3]) and writes the deformed source positions to
 * out ([n_src][3]); the source normals are left as they are, as in Thea.
 * Normals need not be unit length: only the sign of n·n' is used.
 *
 * A cloud must have at least 2 points, finite coordinates and normals, not
 * all points coincident and not all normals zero; otherwise TCB_ERR_INPUT
 * naming the cloud ("source"/"target") and the problem. */
int nricp_register(const float *src, const float *src_nrm, int n_src, const float *dst,
                   const float *dst_nrm, int n_dst, const nricp_params *p, float *out,
                   tcb_error *err);

#endif
