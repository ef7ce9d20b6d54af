/* The atlas transfer over discrete samples (reference-protocol §5.4 steps
 * 1–2): a source point goes to the prediction of frame j at the UV sample
 * whose prediction on frame i is nearest to it. */
#include "tcb/metrics.h"

#include <stdlib.h>
#include <string.h>

#include "tcb/nn.h"

int tcb_atlas_transfer(const float *src, int n, const float *pred_i, const float *pred_j,
                       int m, float *out, tcb_error *err)
{
    if (m < 1) return tcb_fail(err, TCB_ERR_INPUT, "atlas transfer: no predicted points");
    if (n < 0) return tcb_fail(err, TCB_ERR_INPUT, "atlas transfer: negative point count");
    int32_t *idx = malloc((size_t)(n > 0 ? n : 1) * sizeof *idx);
    if (!idx) return tcb_fail(err, TCB_ERR_NOMEM, "atlas transfer: out of memory");
    int rc = tcb_nn_nearest(pred_i, m, src, n, idx, NULL, err);
    for (int k = 0; rc == TCB_OK && k < n; k++)
        memcpy(out + 3 * (size_t)k, pred_j + 3 * (size_t)idx[k], 3 * sizeof(float));
    free(idx);
    return rc;
}
