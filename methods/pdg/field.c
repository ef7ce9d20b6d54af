/* PDG's per-transition translation fields (methods/pdg/field.h). */
#include "methods/pdg/field.h"

#include <math.h>
#include <string.h>

#include "neural/lattice.h"

int tcb_pdg_fields_init(tcb_pdg_fields *f, int levels, int T, double lambda0, double growth, tcb_error *err)
{
    memset(f, 0, sizeof *f);
    if (levels < 1 || levels > TCB_PDG_MAX_LEVELS || T < 1 || !(lambda0 >= 0) || !(growth > 0))
        return tcb_fail(err, TCB_ERR_INPUT, "pdg: %d levels, %d transitions, lambda %g, growth %g", levels, T,
                        lambda0, growth);
    f->levels = levels, f->T = T;
    for (int l = 0; l < levels; l++) {
        f->r[l] = 1 + 2 * l;
        size_t n3 = (size_t)f->r[l] * f->r[l] * f->r[l];
        f->off[l + 1] = f->off[l] + (size_t)T * n3 * 3;
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
    return (size_t)r * r * r * 3;
}

void tcb_pdg_fields_solve(const tcb_pdg_fields *f, const float *U, float *V, double *scratch)
{
    for (int l = 0; l < f->levels; l++)
        for (int g = 0; g < f->T; g++) {
            size_t at = tcb_pdg_level(f, U, g, l) - U;
            tcb_sobolev_solve(&f->sobolev[l], 3, U + at, V + at, scratch);
        }
}

void tcb_pdg_field_forward(const tcb_pdg_fields *f, const float *V, int g, const float *x, int n, float *s,
                           float *y)
{
    memset(s, 0, (size_t)n * 3 * sizeof *s);
    float mean = 1.0f / (float)f->levels;
    for (int l = 0; l < f->levels; l++) tcb_lattice_forward(s, tcb_pdg_level(f, V, g, l), f->r[l], 3, x, n, mean);
    for (size_t i = 0; i < (size_t)n * 3; i++) y[i] = x[i] + TCB_PDG_TSCALE * tanhf(s[i]);
}

void tcb_pdg_field_backward(const tcb_pdg_fields *f, const float *V, int g, const float *x, int n, const float *s,
                            const float *dy, float *dV, float *dx, float *ds)
{
    for (size_t i = 0; i < (size_t)n * 3; i++) {
        float t = tanhf(s[i]);
        ds[i] = dy[i] * TCB_PDG_TSCALE * (1.0f - t * t);
    }
    float mean = 1.0f / (float)f->levels;
    for (int l = 0; l < f->levels; l++) {
        size_t at = tcb_pdg_level(f, V, g, l) - V;
        tcb_lattice_backward(dV + at, ds, f->r[l], 3, x, n, mean);
        if (dx) tcb_lattice_backward_points(dx, ds, V + at, f->r[l], 3, x, n, mean);
    }
    if (dx)
        for (size_t i = 0; i < (size_t)n * 3; i++) dx[i] += dy[i];
}
