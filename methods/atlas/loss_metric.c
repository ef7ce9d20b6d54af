/* Metric-consistency loss with its gradient; see loss_metric.h. */
#include "methods/atlas/loss_metric.h"

#include <math.h>
#include <stddef.h>

#include "methods/atlas/fff.h"

int tcb_atlas_metric_loss(const float *phi_u, const float *phi_v, int B, int M, float weight,
                          double *loss, float *dphi_u, float *dphi_v, tcb_error *err)
{
    if (B < 2 || B % 2 || M < 1)
        return tcb_fail(err, TCB_ERR_INPUT,
                        "atlas metric loss: needs whole pairs and samples (B=%d M=%d)", B, M);
    double k = (double)(B / 2) * M, sum = 0.0;
    for (int pair = 0; pair < B / 2; pair++) {
        size_t a0 = (size_t)(2 * pair) * M * 3, b0 = a0 + (size_t)M * 3;
        for (int m = 0; m < M; m++) {
            size_t a = a0 + 3 * (size_t)m, b = b0 + 3 * (size_t)m;
            tcb_atlas_fff ga = tcb_atlas_fff_at(phi_u + a, phi_v + a);
            tcb_atlas_fff gb = tcb_atlas_fff_at(phi_u + b, phi_v + b);
            double de = ga.e - gb.e, df = ga.f - gb.f, dg = ga.g - gb.g;
            sum += de * de + 2.0 * df * df + dg * dg;
            if (!dphi_u) continue;
            /* ∂e/∂(E_a, F_a, G_a) = 2 (ΔE, 2ΔF, ΔG); shape b gets the negative. */
            double s = 2.0 * weight / k;
            tcb_atlas_fff d = {s * de, 2.0 * s * df, s * dg};
            tcb_atlas_fff_backward(phi_u + a, phi_v + a, d, dphi_u + a, dphi_v + a);
            tcb_atlas_fff_backward(phi_u + b, phi_v + b, (tcb_atlas_fff){-d.e, -d.f, -d.g},
                                   dphi_u + b, dphi_v + b);
        }
    }
    *loss = sum / k;
    if (!isfinite(*loss))
        return tcb_fail(err, TCB_ERR_NUMERIC, "atlas metric loss: not finite");
    return TCB_OK;
}
