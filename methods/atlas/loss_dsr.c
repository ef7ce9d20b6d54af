/* DSR regularizers with their gradient; see loss_dsr.h.
 *
 * Three passes over the B·M samples: the batch means μ_E, μ_G; the terms
 * together with the sums that carry the gradient through those means and
 * the per-shape total areas; then the per-sample gradient.
 *
 * Non-differentiable points, against torch: where A² = 0, torch's sqrt
 * backward divides by 2A = 0 (inf where L_Atot is active for the shape,
 * 0/0 = NaN where it is not). Where EG − F² < 0 the clamp then stops it
 * (torch.maximum and clamp both select a 0 gradient there), but at an exact
 * EG − F² = 0 it reaches E, F, G and poisons the step. We pass no gradient
 * through √ at A = 0 and none through the clamp at EG − F² ≤ 0, i.e. treat
 * A² there as the constant 0. Only exactly degenerate samples differ.
 *
 * Precision: E, F, G and EG − F² are evaluated in double (torch: float32),
 * so a near-degenerate sample whose float32 EG − F² cancels to ≤ 0, giving
 * the weight 1/ε = 1e20, gets its true tiny A² here instead. */
#include "methods/atlas/loss_dsr.h"

#include <math.h>
#include <stdlib.h>

#include "methods/atlas/fff.h"

#define DSR_EPS 1e-20

tcb_atlas_dsr_weights tcb_atlas_dsr_defaults(void)
{
    return (tcb_atlas_dsr_weights){.e = 1.0, .g = 1.0, .skew = 1.0, .stretch = 0.0,
                                   .total_area = 100.0};
}

/* EG − F², unclamped: its sign decides whether the clamp passes gradient. */
static double det(tcb_atlas_fff m) { return m.e * m.g - m.f * m.f; }

/* What the gradient pass needs besides the samples. */
typedef struct dsr_state {
    int B, M, P;
    double k;            /* B·M */
    double mu_e, mu_g;   /* batch means of E and G */
    double s_e, s_g;     /* Σ (E − μ_E)/(A² + ε), Σ (G − μ_G)/(A² + ε): paths through μ */
    double *excess;      /* [B] max(0, Σ_p mean_p A − area_gt) */
} dsr_state;

static void batch_means(const float *phi_u, const float *phi_v, dsr_state *st)
{
    double se = 0.0, sg = 0.0;
    for (size_t i = 0; i < (size_t)st->B * st->M; i++) {
        tcb_atlas_fff m = tcb_atlas_fff_at(phi_u + 3 * i, phi_v + 3 * i);
        se += m.e, sg += m.g;
    }
    st->mu_e = se / st->k, st->mu_g = sg / st->k;
}

static void terms_and_sums(const float *phi_u, const float *phi_v, const double *area_gt,
                           dsr_state *st, tcb_atlas_dsr_terms *t)
{
    *t = (tcb_atlas_dsr_terms){0};
    st->s_e = st->s_g = 0.0;
    double atot = 0.0;
    for (int b = 0; b < st->B; b++) {
        double area = 0.0;
        for (int m = 0; m < st->M; m++) {
            size_t i = ((size_t)b * st->M + m) * 3;
            tcb_atlas_fff g = tcb_atlas_fff_at(phi_u + i, phi_v + i);
            double a2 = fmax(det(g), 0.0), iw = 1.0 / (a2 + DSR_EPS);
            double de = g.e - st->mu_e, dg = g.g - st->mu_g, ds = g.e - g.g;
            t->e += de * de * iw, t->g += dg * dg * iw;
            t->skew += g.f * g.f * iw, t->stretch += ds * ds * iw;
            st->s_e += de * iw, st->s_g += dg * iw;
            area += sqrt(a2);
        }
        /* Equal patches: Σ_p mean_{samples∈p} A = (P/M) Σ_samples A. */
        st->excess[b] = fmax(area * st->P / st->M - area_gt[b], 0.0);
        atot += st->excess[b] * st->excess[b];
    }
    t->e /= st->k, t->g /= st->k, t->skew /= st->k, t->stretch /= st->k;
    t->total_area = atot / st->B;
}

/* ∂(weight · L_sciso)/∂(E, F, G) of one sample of shape b. */
static tcb_atlas_fff sample_grad(tcb_atlas_fff g, int b, const dsr_state *st,
                                 const tcb_atlas_dsr_weights *w, double weight)
{
    double raw = det(g), a2 = fmax(raw, 0.0), iw = 1.0 / (a2 + DSR_EPS);
    double de = g.e - st->mu_e, dg = g.g - st->mu_g, ds = g.e - g.g;
    double s = weight / st->k;
    tcb_atlas_fff d = {
        s * (2.0 * w->e * (de * iw - st->s_e / st->k) + 2.0 * w->stretch * ds * iw),
        s * 2.0 * w->skew * g.f * iw,
        s * (2.0 * w->g * (dg * iw - st->s_g / st->k) - 2.0 * w->stretch * ds * iw),
    };
    /* Through A² in the weights w = 1/(A² + ε) ... */
    double d_a2 = -s * iw * iw *
                  (w->e * de * de + w->g * dg * dg + w->skew * g.f * g.f + w->stretch * ds * ds);
    /* ... and through A = √A² in L_Atot (none at A = 0, see above). */
    if (a2 > 0.0) {
        double d_a = weight * w->total_area * 2.0 * st->excess[b] / st->B * st->P / st->M;
        d_a2 += d_a / (2.0 * sqrt(a2));
    }
    if (raw > 0.0) d.e += d_a2 * g.g, d.f -= 2.0 * d_a2 * g.f, d.g += d_a2 * g.e;
    return d;
}

static void backward(const float *phi_u, const float *phi_v, const dsr_state *st,
                     const tcb_atlas_dsr_weights *w, double weight, float *dphi_u,
                     float *dphi_v)
{
    for (int b = 0; b < st->B; b++)
        for (int m = 0; m < st->M; m++) {
            size_t i = ((size_t)b * st->M + m) * 3;
            tcb_atlas_fff g = tcb_atlas_fff_at(phi_u + i, phi_v + i);
            tcb_atlas_fff_backward(phi_u + i, phi_v + i, sample_grad(g, b, st, w, weight),
                                   dphi_u + i, dphi_v + i);
        }
}

int tcb_atlas_dsr_loss(const float *phi_u, const float *phi_v, int B, int M, int P,
                       const double *area_gt, const tcb_atlas_dsr_weights *w, float weight,
                       double *loss, tcb_atlas_dsr_terms *terms, float *dphi_u, float *dphi_v,
                       tcb_error *err)
{
    if (B < 1 || P < 1 || M < P || M % P)
        return tcb_fail(err, TCB_ERR_INPUT,
                        "atlas DSR loss: needs M a positive multiple of P (B=%d M=%d P=%d)", B, M,
                        P);
    dsr_state st = {.B = B, .M = M, .P = P, .k = (double)B * M};
    st.excess = malloc((size_t)B * sizeof *st.excess);
    if (!st.excess) return tcb_fail(err, TCB_ERR_NOMEM, "atlas DSR loss: out of memory");
    tcb_atlas_dsr_terms t;
    batch_means(phi_u, phi_v, &st);
    terms_and_sums(phi_u, phi_v, area_gt, &st, &t);
    *loss = w->e * t.e + w->g * t.g + w->skew * t.skew + w->stretch * t.stretch +
            w->total_area * t.total_area;
    if (terms) *terms = t;
    int rc = isfinite(*loss) ? TCB_OK
                             : tcb_fail(err, TCB_ERR_NUMERIC, "atlas DSR loss: not finite");
    if (rc == TCB_OK && dphi_u) backward(phi_u, phi_v, &st, w, weight, dphi_u, dphi_v);
    free(st.excess);
    return rc;
}
