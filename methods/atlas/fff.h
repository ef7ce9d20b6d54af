/* The first fundamental form of one UV sample, g = [[E, F], [F, G]] with
 * E = φu·φu, F = φu·φv, G = φv·φv (reference-protocol §2.4), and its
 * pullback onto the tangents. Shared by the metric-consistency loss, the
 * DSR terms and the collapse test. Evaluated in double from the float
 * tangents: EG − F² cancels badly in float on thin patches. */
#ifndef TCB_ATLAS_FFF_H
#define TCB_ATLAS_FFF_H

typedef struct tcb_atlas_fff {
    double e, f, g;
} tcb_atlas_fff;

/* pu, pv: the tangents φ_u, φ_v of one sample, [3] each. */
static inline tcb_atlas_fff tcb_atlas_fff_at(const float *pu, const float *pv)
{
    tcb_atlas_fff m = {0.0, 0.0, 0.0};
    for (int c = 0; c < 3; c++) {
        m.e += (double)pu[c] * pu[c];
        m.f += (double)pu[c] * pv[c];
        m.g += (double)pv[c] * pv[c];
    }
    return m;
}

/* dpu += ∂L/∂φu and dpv += ∂L/∂φv given dm = (∂L/∂E, ∂L/∂F, ∂L/∂G):
 * ∂E/∂φu = 2φu, ∂F/∂φu = φv, ∂F/∂φv = φu, ∂G/∂φv = 2φv. */
static inline void tcb_atlas_fff_backward(const float *pu, const float *pv, tcb_atlas_fff dm,
                                          float *dpu, float *dpv)
{
    for (int c = 0; c < 3; c++) {
        dpu[c] += (float)(2.0 * dm.e * pu[c] + dm.f * pv[c]);
        dpv[c] += (float)(dm.f * pu[c] + 2.0 * dm.g * pv[c]);
    }
}

#endif
