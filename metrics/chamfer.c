/* Symmetric Chamfer distance (reference-protocol §5.5 CD): the mean squared
 * distance from each point of one set to its nearest point of the other,
 * summed over both directions. */
#include "tcb/metrics.h"

#include <stdlib.h>

#include "tcb/nn.h"

/* mean over from[i] of |from[i] − to[nn(i)]|². The neighbour is exact in
 * float; its distance is re-evaluated in double for the accumulation. */
static int mean_nn_d2(const float *from, int nfrom, const float *to, int nto, double *out,
                      tcb_error *err)
{
    int32_t *idx = malloc((size_t)nfrom * sizeof *idx);
    if (!idx) return tcb_fail(err, TCB_ERR_NOMEM, "chamfer: out of memory");
    int rc = tcb_nn_nearest(to, nto, from, nfrom, idx, NULL, err);
    double sum = 0.0;
    for (int i = 0; rc == TCB_OK && i < nfrom; i++) {
        const float *p = from + 3 * (size_t)i, *q = to + 3 * (size_t)idx[i];
        double dx = (double)p[0] - q[0], dy = (double)p[1] - q[1], dz = (double)p[2] - q[2];
        sum += dx * dx + dy * dy + dz * dz;
    }
    free(idx);
    *out = sum / nfrom;
    return rc;
}

int tcb_chamfer(const float *a, int na, const float *b, int nb, double *out, tcb_error *err)
{
    if (na < 1 || nb < 1)
        return tcb_fail(err, TCB_ERR_INPUT, "chamfer: empty point set (%d and %d points)", na,
                        nb);
    double ab, ba;
    int rc = mean_nn_d2(a, na, b, nb, &ab, err);
    if (!rc) rc = mean_nn_d2(b, nb, a, na, &ba, err);
    if (!rc) *out = ab + ba;
    return rc;
}
