/* The tracking error "Corr" of the clip protocol (DynoSurf, PDG, Neu-PiG;
 * DynoSurf's evaluation/utils.py, eval_correspondences_mesh, defines it):
 * tcbench's (GT points carried by the method) and DynoSurf's own (the
 * method's vertices matched to GT points once, on frame 0). */
#include <math.h>
#include <stddef.h>

#include "tcb/metrics.h"
#include "tcb/nn.h"

double tcb_corr_frame(const float *moved, const float *truth, int n)
{
    double sum = 0;
    for (int k = 0; k < n; k++) {
        double dx = (double)moved[3 * k] - truth[3 * k], dy = (double)moved[3 * k + 1] - truth[3 * k + 1],
               dz = (double)moved[3 * k + 2] - truth[3 * k + 2];
        sum += sqrt(dx * dx + dy * dy + dz * dz);
    }
    return n > 0 ? sum / n : NAN;
}

int tcb_corr_mesh_match(const float *pred0, int n, const float *gt0, int ng, int32_t *ind, tcb_error *err)
{
    return tcb_nn_nearest(gt0, ng, pred0, n, ind, NULL, err);
}

double tcb_corr_mesh_frame(const float *pred_t, int n, const float *gt_t, const int32_t *ind)
{
    double sum = 0;
    for (int i = 0; i < n; i++) {
        const float *p = pred_t + 3 * (size_t)i, *q = gt_t + 3 * (size_t)ind[i];
        double dx = (double)p[0] - q[0], dy = (double)p[1] - q[1], dz = (double)p[2] - q[2];
        sum += sqrt(dx * dx + dy * dy + dz * dz);
    }
    return n > 0 ? sum / n : NAN;
}
