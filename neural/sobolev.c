/* Exact Sobolev solve on a lattice through the eigenbasis of its path
 * matrices (neural/sobolev.h). */
#include "neural/sobolev.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "neural/parallel.h"

const char *const tcb_sobolev_laplacian_names[] = {"pcgrid", "graph", NULL};

/* LAPACK's eigensolver of a symmetric tridiagonal matrix (OpenBLAS carries
 * LAPACK; Debian installs no LAPACKE header beside it). */
extern void dstev_(const char *jobz, const int *n, double *d, double *e, double *z, const int *ldz, double *work,
                   int *info);

/* Q (column k the k-th eigenvector) and μ of the path matrix P. */
static int path_eigen(int r, tcb_sobolev_laplacian laplacian, double *Q, double *mu, tcb_error *err)
{
    if (laplacian == TCB_SOBOLEV_GRAPH) {
        for (int k = 0; k < r; k++) {
            double c = sqrt((k ? 2.0 : 1.0) / r);
            mu[k] = 2.0 - 2.0 * cos(M_PI * k / r);
            for (int i = 0; i < r; i++) Q[i * r + k] = c * cos(M_PI * k * (i + 0.5) / r);
        }
        return TCB_OK;
    }
    double *off = malloc((size_t)(r > 1 ? r - 1 : 1) * sizeof *off), *z = malloc((size_t)r * r * sizeof *z),
           *work = malloc((size_t)(2 * r > 2 ? 2 * r - 2 : 1) * sizeof *work);
    int info = -1;
    if (off && z && work) {
        for (int i = 0; i < r; i++) mu[i] = 2.0 * ((i > 0) + (i < r - 1)); /* twice the neighbours */
        for (int i = 0; i + 1 < r; i++) off[i] = -1.0;
        dstev_("V", &r, mu, off, z, &r, work, &info);
        for (int i = 0; i < r; i++) /* z is column-major: z[k·r + i] is component i of vector k */
            for (int k = 0; k < r; k++) Q[i * r + k] = z[(size_t)k * r + i];
    }
    free(off), free(z), free(work);
    if (!off || !z || !work) return tcb_fail(err, TCB_ERR_NOMEM, "Sobolev preconditioner: out of memory");
    if (info) return tcb_fail(err, TCB_ERR_NUMERIC, "Sobolev preconditioner: LAPACK dstev failed (info %d, r = %d)", info, r);
    return TCB_OK;
}

int tcb_sobolev_init(tcb_sobolev *s, int r, double lambda, tcb_sobolev_laplacian laplacian, tcb_error *err)
{
    memset(s, 0, sizeof *s);
    if (r < 1 || r > 1024 || !(lambda >= 0.0) ||
        (laplacian != TCB_SOBOLEV_PCGRID && laplacian != TCB_SOBOLEV_GRAPH))
        return tcb_fail(err, TCB_ERR_INPUT, "Sobolev preconditioner: r = %d, lambda = %g", r, lambda);
    size_t n3 = (size_t)r * r * r;
    s->r = r;
    s->lambda = lambda;
    s->laplacian = laplacian;
    s->Q = malloc((size_t)r * r * sizeof *s->Q);
    s->gain = malloc(n3 * sizeof *s->gain);
    double *mu = malloc((size_t)r * sizeof *mu);
    int rc = !s->Q || !s->gain || !mu ? tcb_fail(err, TCB_ERR_NOMEM, "Sobolev preconditioner: out of memory")
                                      : path_eigen(r, laplacian, s->Q, mu, err);
    if (!rc)
        for (int z = 0; z < r; z++)
            for (int y = 0; y < r; y++)
                for (int x = 0; x < r; x++)
                    s->gain[((size_t)z * r + y) * r + x] = 1.0 / (1.0 + lambda * (mu[x] + mu[y] + mu[z]));
    free(mu);
    if (rc) tcb_sobolev_free(s);
    return rc;
}

void tcb_sobolev_free(tcb_sobolev *s)
{
    free(s->Q);
    free(s->gain);
    memset(s, 0, sizeof *s);
}

/* In place along one axis of a [r][r][r][F] array (element stride `step`
 * along the axis): a ← Qᵀ a (to the eigenbasis) or a ← Q a (back). The
 * r² lines along the axis are independent: side by side on the threads,
 * each computed alike on any number of them. Line L starts at node
 * (L / s)·s·r + L % s, s the axis's node stride (1, r or r²). */
static void transform_axis(const double *Q, int r, int F, size_t step, int to_basis, double *a)
{
    size_t s = step / (size_t)F, lines = (size_t)r * r;
#pragma omp parallel for schedule(static) if ((double)lines * F * r * r > TCB_PAR_MIN)
    for (size_t L = 0; L < lines; L++) {
        double line[1024];
        size_t base = L / s * s * (size_t)r + L % s;
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
    for (size_t i = 0; i < n3 * (size_t)F; i++) scratch[i] = u[i];
    for (int a = 0; a < 3; a++) transform_axis(s->Q, r, F, steps[a], 1, scratch);
    for (size_t node = 0; node < n3; node++)
        for (int f = 0; f < F; f++) scratch[node * (size_t)F + (size_t)f] *= s->gain[node];
    for (int a = 0; a < 3; a++) transform_axis(s->Q, r, F, steps[a], 0, scratch);
    for (size_t i = 0; i < n3 * (size_t)F; i++) v[i] = (float)scratch[i];
}

void tcb_sobolev_apply(const tcb_sobolev *s, int F, const float *v, float *u)
{
    int r = s->r;
    double per_neighbour = s->laplacian == TCB_SOBOLEV_PCGRID ? 2.0 : 1.0;
    for (int z = 0; z < r; z++)
        for (int y = 0; y < r; y++)
            for (int x = 0; x < r; x++) {
                size_t node = ((size_t)z * r + y) * r + x;
                const int c[3] = {x, y, z};
                const size_t stride[3] = {1, (size_t)r, (size_t)r * r};
                for (int f = 0; f < F; f++) {
                    /* each neighbour adds (1 or 2)·own − its value */
                    double own = v[node * (size_t)F + (size_t)f], acc = own, diag = own * per_neighbour;
                    for (int a = 0; a < 3; a++) {
                        if (c[a] > 0) acc += s->lambda * (diag - v[(node - stride[a]) * (size_t)F + (size_t)f]);
                        if (c[a] < r - 1) acc += s->lambda * (diag - v[(node + stride[a]) * (size_t)F + (size_t)f]);
                    }
                    u[node * (size_t)F + (size_t)f] = (float)acc;
                }
            }
}
