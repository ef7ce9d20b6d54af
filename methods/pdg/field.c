/* PDG's per-transition fields and their per-point steps (methods/pdg/field.h). */
#include "methods/pdg/field.h"

#include <math.h>
#include <string.h>

#include "neural/lattice.h"

const char *const tcb_pdg_rotation_names[] = {"released", "cayley", NULL};

int tcb_pdg_fields_init(tcb_pdg_fields *f, int levels, int T, tcb_pdg_rotation rotation, double lambda0,
                        double growth, tcb_error *err)
{
    memset(f, 0, sizeof *f);
    if (levels < 1 || levels > TCB_PDG_MAX_LEVELS || T < 1 || !(lambda0 >= 0) || !(growth > 0) ||
        (rotation != TCB_PDG_RELEASED && rotation != TCB_PDG_CAYLEY))
        return tcb_fail(err, TCB_ERR_INPUT, "pdg: %d levels, %d transitions, lambda %g, growth %g, rotation %d",
                        levels, T, lambda0, growth, (int)rotation);
    f->levels = levels, f->T = T, f->rotation = rotation, f->C = rotation == TCB_PDG_CAYLEY ? 6 : 3;
    for (int l = 0; l < levels; l++) {
        f->r[l] = 1 + 2 * l;
        size_t n3 = (size_t)f->r[l] * f->r[l] * f->r[l];
        f->off[l + 1] = f->off[l] + (size_t)T * n3 * f->C;
        int rc = tcb_sobolev_init(&f->sobolev[l], f->r[l], lambda0 * pow(growth, l), TCB_SOBOLEV_PCGRID, err);
        if (rc) {
            tcb_pdg_fields_free(f);
            return rc;
        }
    }
    return TCB_OK;
}

void tcb_pdg_fields_free(tcb_pdg_fields *f)
{
    for (int l = 0; l < f->levels; l++) tcb_sobolev_free(&f->sobolev[l]);
    memset(f, 0, sizeof *f);
}

size_t tcb_pdg_fields_scratch(const tcb_pdg_fields *f)
{
    int r = f->r[f->levels - 1];
    return (size_t)r * r * r * f->C;
}

void tcb_pdg_fields_solve(const tcb_pdg_fields *f, const float *U, float *V, double *scratch)
{
    for (int l = 0; l < f->levels; l++)
        for (int g = 0; g < f->T; g++) {
            size_t at = tcb_pdg_level(f, U, g, l) - U;
            tcb_sobolev_solve(&f->sobolev[l], f->C, U + at, V + at, scratch);
        }
}

/* ---- the Cayley rotation of one point ---- */

void tcb_pdg_cayley_forward(const float r[3], float R[9])
{
    /* with K² = r rᵀ − |r|² I, (I − K)⁻¹ = I + (K + K²)/(1 + |r|²), so
     * R = I + 2 (K + K²)/(1 + |r|²): no solve */
    float rr = r[0] * r[0] + r[1] * r[1] + r[2] * r[2], c = 2.0f / (1.0f + rr);
    const float K[9] = {0, -r[2], r[1], r[2], 0, -r[0], -r[1], r[0], 0};
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            float id = i == j ? 1.0f : 0.0f;
            R[3 * i + j] = id + c * (K[3 * i + j] + r[i] * r[j] - id * rr);
        }
}

void tcb_pdg_cayley_backward(const float r[3], const float dR[9], float dr[3])
{
    /* ⟨dR, R⟩ = tr dR + 2φ/s, s = 1 + |r|², φ = ⟨dR, K⟩ + rᵀ dR r − |r|² tr dR
     * and ⟨dR, K⟩ = r·w, w the skew part of dR as a vector:
     * ∂/∂r = (2/s)(w + (dR + dRᵀ) r − 2 tr(dR) r) − (4/s²) φ r */
    float rr = r[0] * r[0] + r[1] * r[1] + r[2] * r[2], s = 1.0f + rr, tr = dR[0] + dR[4] + dR[8];
    const float w[3] = {dR[7] - dR[5], dR[2] - dR[6], dR[3] - dR[1]};
    float sym[3], phi = -rr * tr;
    for (int i = 0; i < 3; i++) {
        float Gr = 0.0f, GTr = 0.0f;
        for (int j = 0; j < 3; j++) Gr += dR[3 * i + j] * r[j], GTr += dR[3 * j + i] * r[j];
        sym[i] = Gr + GTr;
        phi += r[i] * (w[i] + Gr);
    }
    for (int i = 0; i < 3; i++)
        dr[i] = 2.0f / s * (w[i] + sym[i] - 2.0f * tr * r[i]) - 4.0f / (s * s) * phi * r[i];
}

/* ---- the cayley variant's step of one point ---- */

/* The point's step [R | t] from its sample s [6] = (r, s_t); th = tanh(s_t). */
static void cayley_step(const float *s, float R[9], float t[3], float th[3])
{
    tcb_pdg_cayley_forward(s, R);
    for (int k = 0; k < 3; k++) th[k] = tanhf(s[3 + k]), t[k] = TCB_PDG_TSCALE * th[k];
}

/* out [3][4] = A · [R | t] (A [3][4], NULL: the identity). */
static void compose(const float *A, const float R[9], const float t[3], float out[12])
{
    for (int a = 0; a < 3; a++) {
        for (int b = 0; b < 3; b++) out[4 * a + b] = A ? 0.0f : R[3 * a + b];
        out[4 * a + 3] = A ? A[4 * a + 3] : t[a];
        for (int k = 0; A && k < 3; k++) {
            for (int b = 0; b < 3; b++) out[4 * a + b] += A[4 * a + k] * R[3 * k + b];
            out[4 * a + 3] += A[4 * a + k] * t[k];
        }
    }
}

/* Point i (its sample s [6], its x [3]): y [3] = A' x0, A' [3][4] =
 * A · [R | t] kept in c->A_out; without a carry A = I and x0 = x. */
static void cayley_point_forward(const float *s, const float *x, const tcb_pdg_carry *c, size_t i, float *y)
{
    float R[9], t[3], th[3], A[12];
    cayley_step(s, R, t, th);
    const float *x0 = c ? c->x0 + 3 * i : x;
    compose(c && c->A ? c->A + TCB_PDG_AFFINE * i : NULL, R, t, A);
    if (c && c->A_out) memcpy(c->A_out + TCB_PDG_AFFINE * i, A, sizeof A);
    for (int a = 0; a < 3; a++) y[a] = A[4 * a] * x0[0] + A[4 * a + 1] * x0[1] + A[4 * a + 2] * x0[2] + A[4 * a + 3];
}

/* Point i: ds [6] = ∂ℓ/∂s from dy [3] and c->dA_out [3][4], through
 * G [3][4] = ∂ℓ/∂A' = dA_out + dy [x0ᵀ 1]; c->dA [3][4] += ∂ℓ/∂A (A =
 * [B | b] gets G_B Rᵀ + g tᵀ and g, G = [G_B | g]); without a carry
 * dx [3] += Rᵀ dy (y = R x + t). */
static void cayley_point_backward(const float *s, const float *x, const float *dy, const tcb_pdg_carry *c, size_t i,
                                  float *ds, float *dx)
{
    float R[9], t[3], th[3], G[12], dR[9], dt[3];
    cayley_step(s, R, t, th);
    const float *x0 = c ? c->x0 + 3 * i : x, *B = c && c->A ? c->A + TCB_PDG_AFFINE * i : NULL,
                *later = c && c->dA_out ? c->dA_out + TCB_PDG_AFFINE * i : NULL;
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 4; b++) G[4 * a + b] = dy[a] * (b < 3 ? x0[b] : 1.0f) + (later ? later[4 * a + b] : 0.0f);
    /* A' = [B R | B t + b]: dR = Bᵀ G_B, dt = Bᵀ g */
    for (int a = 0; a < 3; a++) {
        for (int b = 0; b < 3; b++) {
            dR[3 * a + b] = 0.0f;
            for (int k = 0; k < 3; k++) dR[3 * a + b] += (B ? B[4 * k + a] : k == a) * G[4 * k + b];
        }
        dt[a] = 0.0f;
        for (int k = 0; k < 3; k++) dt[a] += (B ? B[4 * k + a] : k == a) * G[4 * k + 3];
    }
    float *dA = c && c->dA ? c->dA + TCB_PDG_AFFINE * i : NULL;
    for (int a = 0; dA && a < 3; a++) {
        for (int b = 0; b < 3; b++) {
            float sum = G[4 * a + 3] * t[b];
            for (int k = 0; k < 3; k++) sum += G[4 * a + k] * R[3 * b + k];
            dA[4 * a + b] += sum;
        }
        dA[4 * a + 3] += G[4 * a + 3];
    }
    tcb_pdg_cayley_backward(s, dR, ds);
    for (int k = 0; k < 3; k++) ds[3 + k] = dt[k] * TCB_PDG_TSCALE * (1.0f - th[k] * th[k]);
    for (int a = 0; dx && a < 3; a++) dx[a] += R[a] * dy[0] + R[3 + a] * dy[1] + R[6 + a] * dy[2];
}

/* ---- the field ---- */

void tcb_pdg_field_forward(const tcb_pdg_fields *f, const float *V, int g, const float *x, int n,
                           const tcb_pdg_carry *c, float *s, float *y)
{
    memset(s, 0, (size_t)n * f->C * sizeof *s);
    float mean = 1.0f / (float)f->levels;
    for (int l = 0; l < f->levels; l++) tcb_lattice_forward(s, tcb_pdg_level(f, V, g, l), f->r[l], f->C, x, n, mean);
    if (f->rotation == TCB_PDG_CAYLEY) {
        for (size_t i = 0; i < (size_t)n; i++) cayley_point_forward(s + 6 * i, x + 3 * i, c, i, y + 3 * i);
        return;
    }
    for (size_t i = 0; i < (size_t)n * 3; i++) y[i] = x[i] + TCB_PDG_TSCALE * tanhf(s[i]);
}

void tcb_pdg_field_backward(const tcb_pdg_fields *f, const float *V, int g, const float *x, int n,
                            const tcb_pdg_carry *c, const float *s, const float *dy, float *dV, float *dx, float *ds)
{
    int cayley = f->rotation == TCB_PDG_CAYLEY;
    if (cayley)
        for (size_t i = 0; i < (size_t)n; i++)
            cayley_point_backward(s + 6 * i, x + 3 * i, dy + 3 * i, c, i, ds + 6 * i, dx && !c ? dx + 3 * i : NULL);
    else
        for (size_t i = 0; i < (size_t)n * 3; i++) {
            float t = tanhf(s[i]);
            ds[i] = dy[i] * TCB_PDG_TSCALE * (1.0f - t * t);
        }
    float mean = 1.0f / (float)f->levels;
    for (int l = 0; l < f->levels; l++) {
        size_t at = tcb_pdg_level(f, V, g, l) - V;
        tcb_lattice_backward(dV + at, ds, f->r[l], f->C, x, n, mean);
        if (dx) tcb_lattice_backward_points(dx, ds, V + at, f->r[l], f->C, x, n, mean);
    }
    if (dx && !cayley) /* y = x + t */
        for (size_t i = 0; i < (size_t)n * 3; i++) dx[i] += dy[i];
}
