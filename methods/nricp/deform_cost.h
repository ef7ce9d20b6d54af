/* What propagate_deform's chains cost (methods/nricp/deform.c): the
 * method's cost estimate (nricp.c) and bench_nricp_deform, which compares
 * it with the chains a split really takes, share it. */
#ifndef TCB_NRICP_DEFORM_COST_H
#define TCB_NRICP_DEFORM_COST_H

/* Registrations the chains of n uniformly drawn pairs (j ≠ i) over F
 * frames take, in expectation. */
double nricp_deform_expected_steps(int n_frames, int n_pairs);

#endif
