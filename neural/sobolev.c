/* Exact Sobolev solve on a lattice through its DCT eigenbasis
 * (neural/sobolev.h). */
#include "neural/sobolev.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

int tcb_sobolev_init(tcb_sobolev *s, int r, double lambda, tcb_error *err)
{
    memset(s, 0, sizeof *s);
    if (r < 1 || r > 1024 || !(lambda >= 0.0))
        return tcb_fail(err, TCB_ERR_INPUT, "Sobolev preconditioner: r = %d, lambda = %g", r, lambda);
    size_t n3 = (size_t)r * r * r;
    s->r = r;
    s->lambda = lambda;
    s->Q = malloc((size_t)r * r * sizeof *s->Q);
    s->gain = malloc(n3 * sizeof *s->gain);
    double *mu = malloc((size_t)r * sizeof *mu);
    if (!s->Q || !s->gain || !mu) {
        free(mu);
        tcb_sobolev_free(s);
        return tcb_fail(err, TCB_ERR_NOMEM, "Sobolev preconditioner: out of memory");
    }
    for (int k = 0; k < r; k++) {
        double c = sqrt((k ? 2.0 : 1.0) / r);
        mu[k] = 2.0 - 2.0 * cos(M_PI * k / r);
        for (int i = 0; i < r; i++) s->Q[i * r + k] = c * cos(M_PI * k * (i + 0.5) / r);
    }
    for (int z = 0; z < r; z++)
        for (int y = 0; y < r; y++)
            for (int x = 0; x < r; x++)
                s->gain[((size_t)z * r + y) * r + x] = 1.0 / (1.0 + lambda * (mu[x] + mu[y] + mu[z]));
    free(mu);
    return TCB_OK;
}

void tcb_sobolev_free(tcb_sobolev *s)
{
    free(s->Q);
    free(s->gain);
    memset(s, 0, sizeof *s);
}

/* In place along one axis of a [r][r][r][F] array (element stride `step`
 * along the axis): a ← Qᵀ a (to the eigenbasis) or a ← Q a (back). */
static void transform_axis(const double *Q, int r, int F, size_t step, int to_basis, double *a,
                           double *line)
{
    size_t n3 = (size_t)r * r * r;
    for (size_t base = 0; base < n3; base++) {
        /* base enumerates nodes; take those whose coordinate on this axis is 0. */
        if ((base * (size_t)F / step) % (size_t)r) continue;
        for (int f = 0; f < F; f++) {
            double *p = a + base * (size_t)F + (size_t)f;
            for (int i = 0; i < r; i++) line[i] = p[(size_t)i * step];
            for (int k = 0; k < r; k++) {
                double acc = 0.0;
                for (int i = 0; i < r; i++)
                    acc += (to_basis ? Q[i * r + k] : Q[k * r + i]) * line[i];
                p[(size_t)k * step] = acc;
            }
        }
    }
}

void tcb_sobolev_solve(const tcb_sobolev *s, int F, const float *u, float *v, double *scratch)
{
    int r = s->r;
    size_t n3 = (size_t)r * r * r, steps[3] = {(size_t)F, (size_t)F * r, (size_t)F * r * r};
    double line[1024];
    for (size_t i = 0; i < n3 * (size_t)F; i++) scratch[i] = u[i];
    for (int a = 0; a < 3; a++) transform_axis(s->Q, r, F, steps[a], 1, scratch, line);
    for (size_t node = 0; node < n3; node++)
        for (int f = 0; f < F; f++) scratch[node * (size_t)F + (size_t)f] *= s->gain[node];
    for (int a = 0; a < 3; a++) transform_axis(s->Q, r, F, steps[a], 0, scratch, line);
    for (size_t i = 0; i < n3 * (size_t)F; i++) v[i] = (float)scratch[i];
}

void tcb_sobolev_apply(const tcb_sobolev *s, int F, const float *v, float *u)
{
    int r = s->r;
    for (int z = 0; z < r; z++)
        for (int y = 0; y < r; y++)
            for (int x = 0; x < r; x++) {
                size_t node = ((size_t)z * r + y) * r + x;
                const int c[3] = {x, y, z};
                const size_t stride[3] = {1, (size_t)r, (size_t)r * r};
                for (int f = 0; f < F; f++) {
                    double own = v[node * (size_t)F + (size_t)f], acc = own;
                    for (int a = 0; a < 3; a++) {
                        if (c[a] > 0) acc += s->lambda * (own - v[(node - stride[a]) * (size_t)F + (size_t)f]);
                        if (c[a] < r - 1) acc += s->lambda * (own - v[(node + stride[a]) * (size_t)F + (size_t)f]);
                    }
                    u[node * (size_t)F + (size_t)f] = (float)acc;
                }
            }
}
