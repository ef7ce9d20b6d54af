/* Collapsed patches; see collapse.h. */
#include "methods/atlas/collapse.h"

#include <stdlib.h>

#include "methods/atlas/fff.h"

#define COLLAPSE_RATIO 1e-3
#define COLLAPSE_EPS 1e-30

/* alive[p] |= patch p of this shape is not collapsed. ap: [P] scratch. */
static void mark_alive(const float *phi_u, const float *phi_v, int M, int P, double *ap,
                       unsigned char *alive)
{
    int per = M / P;
    double mean = 0.0;
    for (int p = 0; p < P; p++) {
        double sum = 0.0;
        for (int k = p * per; k < (p + 1) * per; k++) {
            tcb_atlas_fff g = tcb_atlas_fff_at(phi_u + 3 * (size_t)k, phi_v + 3 * (size_t)k);
            sum += g.e * g.g - g.f * g.f;
        }
        ap[p] = sum / per;
        mean += ap[p];
    }
    mean /= P;
    /* Written as "not collapsed" so that a NaN ratio keeps the patch, as
     * numpy's `ratio < 1e-3` being False does. */
    for (int p = 0; p < P; p++)
        if (!(ap[p] / (mean + COLLAPSE_EPS) < COLLAPSE_RATIO)) alive[p] = 1;
}

int tcb_atlas_kept_patches(const float *phi_u, const float *phi_v, int S, int M, int P,
                           int n_pts, int *kept, int *n_kept, int *m_per_patch, tcb_error *err)
{
    if (S < 1 || P < 1 || M < P || M % P || n_pts < P)
        return tcb_fail(err, TCB_ERR_INPUT,
                        "atlas collapse: bad sizes (S=%d M=%d P=%d n_pts=%d)", S, M, P, n_pts);
    double *ap = malloc((size_t)P * sizeof *ap);
    unsigned char *alive = calloc((size_t)P, 1);
    if (!ap || !alive) {
        free(ap), free(alive);
        return tcb_fail(err, TCB_ERR_NOMEM, "atlas collapse: out of memory");
    }
    for (int s = 0; s < S; s++)
        mark_alive(phi_u + (size_t)s * M * 3, phi_v + (size_t)s * M * 3, M, P, ap, alive);
    int n = 0;
    for (int p = 0; p < P; p++)
        if (alive[p]) kept[n++] = p;
    if (n == 0)
        for (; n < P; n++) kept[n] = n;
    free(ap), free(alive);
    *n_kept = n;
    *m_per_patch = n_pts / n;
    return TCB_OK;
}
