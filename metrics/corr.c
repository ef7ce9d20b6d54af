/* The tracking error "Corr" of the clip protocol (DynoSurf, PDG, Neu-PiG;
 * DynoSurf's evaluation/utils.py, eval_correspondences_mesh, defines it). */
#include <math.h>

#include "tcb/metrics.h"

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
