#include "methods/baselines/stateless.h"

#include <stdio.h>

#include "methods/params.h"

int tcb_stateless_create(const char *where, const char *params_json, void **self, tcb_error *err)
{
    static const char *const no_keys[] = {NULL};
    cJSON *params;
    int rc = tcb_params_parse(params_json, where, no_keys, &params, err);
    cJSON_Delete(params);
    *self = NULL;
    return rc;
}

int tcb_stateless_fit(void *self, const tcb_sequence *seq, const tcb_fit_ctx *ctx, tcb_error *err)
{
    (void)self, (void)seq, (void)ctx, (void)err;
    return TCB_OK;
}

void tcb_stateless_destroy(void *self) { (void)self; }

void tcb_stateless_estimate(void *self, const tcb_cost_query *q, tcb_cost_estimate *out)
{
    (void)self, (void)q;
    out->fit_s = out->eval_s = 0;
    snprintf(out->basis, sizeof out->basis, "no model");
}
