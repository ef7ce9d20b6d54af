/* The Large-Steps parametrisation of a mesh (tcb/large_steps.h). */
#include "tcb/large_steps.h"

#include <stdlib.h>
#include <string.h>

#include "tcb/geodesic.h"

/* M's lower triangle: 1 + λ·degree on the diagonal, −λ per edge. */
static int factor_system(tcb_large_steps *ls, const tcb_edge_graph *g, tcb_error *err)
{
    int n_entries = ls->nv + ls->ne;
    int *rows = malloc((size_t)n_entries * sizeof *rows), *cols = malloc((size_t)n_entries * sizeof *cols);
    double *vals = malloc((size_t)n_entries * sizeof *vals);
    int rc = TCB_OK;
    if (!rows || !cols || !vals) rc = tcb_fail(err, TCB_ERR_NOMEM, "large steps: out of memory");
    for (int v = 0; !rc && v < ls->nv; v++) {
        rows[v] = cols[v] = v;
        vals[v] = 1.0 + ls->lambda * (g->offsets[v + 1] - g->offsets[v]);
    }
    for (int e = 0; !rc && e < ls->ne; e++) {
        int a = ls->edges[2 * e], b = ls->edges[2 * e + 1]; /* a < b */
        rows[ls->nv + e] = b, cols[ls->nv + e] = a, vals[ls->nv + e] = -ls->lambda;
    }
    if (!rc) rc = tcb_cholesky_factor(ls->nv, n_entries, rows, cols, vals, &ls->factor, err);
    free(rows), free(cols), free(vals);
    return rc;
}

int tcb_large_steps_init(tcb_large_steps *ls, int nv, const int32_t *faces, int nf, double lambda,
                         tcb_error *err)
{
    memset(ls, 0, sizeof *ls);
    if (nv < 1 || nf < 1 || !(lambda >= 0.0))
        return tcb_fail(err, TCB_ERR_INPUT, "large steps: %d vertices, %d faces, lambda %g", nv, nf, lambda);
    tcb_edge_graph g;
    int rc = tcb_edge_graph_build(faces, nf, nv, &g, err);
    if (rc) return rc;
    ls->nv = nv, ls->lambda = lambda;
    ls->edges = malloc(2 * (size_t)(g.n_edges ? g.n_edges : 1) * sizeof *ls->edges);
    if (!ls->edges) rc = tcb_fail(err, TCB_ERR_NOMEM, "large steps: out of memory");
    for (int a = 0; !rc && a < nv; a++)
        for (int e = g.offsets[a]; e < g.offsets[a + 1]; e++)
            if (g.adj[e] > a) ls->edges[2 * ls->ne] = a, ls->edges[2 * ls->ne++ + 1] = g.adj[e];
    if (!rc) rc = factor_system(ls, &g, err);
    tcb_edge_graph_free(&g);
    if (rc) tcb_large_steps_free(ls);
    return rc;
}

void tcb_large_steps_free(tcb_large_steps *ls)
{
    free(ls->edges);
    tcb_cholesky_free(ls->factor);
    memset(ls, 0, sizeof *ls);
}

void tcb_large_steps_apply(const tcb_large_steps *ls, const float *v, float *u)
{
    double lam = ls->lambda;
    for (int i = 0; i < 3 * ls->nv; i++) u[i] = v[i];
    for (int e = 0; e < ls->ne; e++) { /* λ(D − A)v, one edge at a time */
        int a = ls->edges[2 * e], b = ls->edges[2 * e + 1];
        for (int d = 0; d < 3; d++) {
            float diff = (float)(lam * ((double)v[3 * a + d] - v[3 * b + d]));
            u[3 * a + d] += diff;
            u[3 * b + d] -= diff;
        }
    }
}

int tcb_large_steps_solve(const tcb_large_steps *ls, const float *b, float *x, tcb_error *err)
{
    double *work = malloc(3 * (size_t)ls->nv * sizeof *work);
    if (!work) return tcb_fail(err, TCB_ERR_NOMEM, "large steps: out of memory");
    for (int i = 0; i < 3 * ls->nv; i++) work[i] = b[i];
    int rc = tcb_cholesky_solve(ls->factor, work, 3, err);
    if (!rc)
        for (int i = 0; i < 3 * ls->nv; i++) x[i] = (float)work[i];
    free(work);
    return rc;
}
