/* nearest — each vertex of frame i goes to the nearest GT vertex of frame j
 * by position, with no model at all. It is the floor a method must beat to
 * be worth anything: on small motions it is already strong (on walking cat
 * it beats the paper's own nrICP row). The harness's projection onto frame
 * j's vertices does the whole job, so transfer returns the points as given. */
#include <string.h>

#include "methods/baselines/stateless.h"
#include "methods/builtin.h"

static int nearest_create(const char *params_json, void **self, tcb_error *err)
{
    return tcb_stateless_create("nearest.params", params_json, self, err);
}

static int nearest_transfer(void *self, const tcb_sequence *seq, int i, int j, const float *src, int n,
                            float *out, tcb_rng *rng, tcb_error *err)
{
    (void)self, (void)seq, (void)i, (void)j, (void)rng, (void)err;
    memcpy(out, src, (size_t)n * 3 * sizeof *out);
    return TCB_OK;
}

const tcb_method_ops tcb_method_nearest = {
    .abi_version = TCB_METHOD_ABI_VERSION,
    .name = "nearest",
    .description = "nearest GT vertex of frame j by position: the no-model floor to beat",
    .create = nearest_create,
    .fit = tcb_stateless_fit,
    .transfer = nearest_transfer,
    .destroy = tcb_stateless_destroy,
    .estimate = tcb_stateless_estimate,
};
