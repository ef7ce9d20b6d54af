/* oracle — the true transfer, a sanity row: vertex k of frame i goes to
 * vertex k of frame j, so m_sL2 = rank = 0 and AUC = 100 exactly. It is the
 * one method allowed to use the fact that vertex ids correspond; a report
 * where it is not perfect means the harness or the metrics are broken. */
#include <stdlib.h>
#include <string.h>

#include "methods/baselines/stateless.h"
#include "methods/builtin.h"

static int oracle_create(const char *params_json, void **self, tcb_error *err)
{
    return tcb_stateless_create("oracle.params", params_json, self, err);
}

static int oracle_transfer(void *self, const tcb_sequence *seq, int i, int j, const float *src, int n,
                           float *out, tcb_rng *rng, tcb_error *err)
{
    (void)self, (void)i, (void)src, (void)rng;
    if (n != seq->n_verts)
        return tcb_fail(err, TCB_ERR_INPUT,
                        "oracle: can only transfer the %d GT vertices of a frame, got %d points", seq->n_verts,
                        n);
    memcpy(out, tcb_seq_frame(seq, j), (size_t)n * 3 * sizeof *out);
    return TCB_OK;
}

const tcb_method_ops tcb_method_oracle = {
    .abi_version = TCB_METHOD_ABI_VERSION,
    .name = "oracle",
    .description = "ground-truth transfer (vertex k -> vertex k): the perfect score, a harness check",
    .create = oracle_create,
    .fit = tcb_stateless_fit,
    .transfer = oracle_transfer,
    .destroy = tcb_stateless_destroy,
    .estimate = tcb_stateless_estimate,
};
