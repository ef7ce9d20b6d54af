/* Shared pieces of the model-free sanity methods (oracle, nearest): they
 * take no params, fit nothing and own no state. */
#ifndef TCB_METHODS_STATELESS_H
#define TCB_METHODS_STATELESS_H

#include "tcb/method.h"

/* Accepts only an empty params object; `where` names it in messages. */
int tcb_stateless_create(const char *where, const char *params_json, void **self, tcb_error *err);
int tcb_stateless_fit(void *self, const tcb_sequence *seq, const tcb_fit_ctx *ctx, tcb_error *err);
void tcb_stateless_destroy(void *self);
/* Nothing to fit, nothing per pair beyond the harness's own projection. */
void tcb_stateless_estimate(void *self, const tcb_cost_query *q, tcb_cost_estimate *out);

#endif
