/* tcb/cholesky.h over CHOLMOD. CHOLMOD keeps its workspace in a
 * cholmod_common; each factor owns one, and a solve borrows a private one
 * so that a factor can be shared between threads read-only. */
#include "tcb/cholesky.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <suitesparse/cholmod.h>

struct tcb_cholesky {
    int n;
    cholmod_factor *factor;
};

/* CHOLMOD's defaults, made deterministic and quiet: a simplicial LLᵀ (the
 * supernodal one calls a threaded BLAS; the simplicial default is LDLᵀ,
 * which factors an indefinite matrix without a word), one ordering (AMD),
 * and no printing: failures come back as cholmod_common.status. */
static void start(cholmod_common *c)
{
    cholmod_start(c);
    c->print = 0;
    c->error_handler = NULL;
    c->supernodal = CHOLMOD_SIMPLICIAL;
    c->final_ll = 1;
    c->nmethods = 1;
    c->method[0].ordering = CHOLMOD_AMD;
    c->postorder = 1;
}

static int check_triplets(int n, int n_entries, const int *rows, const int *cols, const double *vals,
                          tcb_error *err)
{
    if (n < 1 || n_entries < 1 || !rows || !cols || !vals)
        return tcb_fail(err, TCB_ERR_INPUT, "cholesky: a %d × %d matrix with %d entries", n, n, n_entries);
    for (int e = 0; e < n_entries; e++) {
        if (rows[e] < 0 || rows[e] >= n || cols[e] < 0 || cols[e] >= n)
            return tcb_fail(err, TCB_ERR_INPUT, "cholesky: entry %d at (%d, %d) of a %d × %d matrix", e, rows[e],
                            cols[e], n, n);
        if (rows[e] < cols[e])
            return tcb_fail(err, TCB_ERR_INPUT, "cholesky: entry %d at (%d, %d) is above the diagonal", e, rows[e],
                            cols[e]);
        if (!isfinite(vals[e]))
            return tcb_fail(err, TCB_ERR_NUMERIC, "cholesky: entry %d at (%d, %d) is not finite", e, rows[e], cols[e]);
    }
    return TCB_OK;
}

static cholmod_sparse *to_sparse(int n, int n_entries, const int *rows, const int *cols, const double *vals,
                                 cholmod_common *c)
{
    cholmod_triplet *t = cholmod_allocate_triplet((size_t)n, (size_t)n, (size_t)n_entries, -1, CHOLMOD_REAL, c);
    if (!t) return NULL;
    int *ti = t->i, *tj = t->j;
    double *tx = t->x;
    for (int e = 0; e < n_entries; e++) {
        ti[e] = rows[e];
        tj[e] = cols[e];
        tx[e] = vals[e];
    }
    t->nnz = (size_t)n_entries;
    cholmod_sparse *a = cholmod_triplet_to_sparse(t, (size_t)n_entries, c);
    cholmod_free_triplet(&t, c);
    return a;
}

int tcb_cholesky_factor(int n, int n_entries, const int *rows, const int *cols, const double *vals,
                        tcb_cholesky **out, tcb_error *err)
{
    *out = NULL;
    int rc = check_triplets(n, n_entries, rows, cols, vals, err);
    if (rc) return rc;
    tcb_cholesky *f = calloc(1, sizeof *f);
    if (!f) return tcb_fail(err, TCB_ERR_NOMEM, "cholesky: out of memory");
    f->n = n;
    cholmod_common c;
    start(&c);
    cholmod_sparse *a = to_sparse(n, n_entries, rows, cols, vals, &c);
    if (a) f->factor = cholmod_analyze(a, &c);
    if (f->factor) cholmod_factorize(a, f->factor, &c);
    int status = c.status;
    size_t minor = f->factor ? f->factor->minor : 0;
    cholmod_free_sparse(&a, &c);
    if (status == CHOLMOD_NOT_POSDEF)
        rc = tcb_fail(err, TCB_ERR_NUMERIC, "cholesky: the %d × %d matrix is not positive definite (pivot %zu)", n, n,
                      minor);
    else if (status == CHOLMOD_OUT_OF_MEMORY || !f->factor)
        rc = tcb_fail(err, TCB_ERR_NOMEM, "cholesky: out of memory factoring a %d × %d matrix", n, n);
    else if (status < CHOLMOD_OK)
        rc = tcb_fail(err, TCB_ERR_NUMERIC, "cholesky: CHOLMOD failed (status %d)", status);
    if (rc) {
        cholmod_free_factor(&f->factor, &c);
        free(f);
        f = NULL;
    }
    cholmod_finish(&c);
    *out = f;
    return rc;
}

int tcb_cholesky_solve(const tcb_cholesky *f, double *b, int k, tcb_error *err)
{
    if (!f || !b || k < 1) return tcb_fail(err, TCB_ERR_INPUT, "cholesky: a solve with %d right-hand sides", k);
    cholmod_common c;
    start(&c);
    int rc = TCB_OK;
    cholmod_dense *rhs = cholmod_allocate_dense((size_t)f->n, (size_t)k, (size_t)f->n, CHOLMOD_REAL, &c), *x = NULL;
    if (rhs) {
        double *r = rhs->x; /* column-major */
        for (int i = 0; i < f->n; i++)
            for (int j = 0; j < k; j++) r[(size_t)j * f->n + i] = b[(size_t)i * k + j];
        /* cholmod_solve only reads the factor: the cast is CHOLMOD's missing const. */
        x = cholmod_solve(CHOLMOD_A, (cholmod_factor *)f->factor, rhs, &c);
    }
    if (x) {
        const double *s = x->x;
        for (int i = 0; i < f->n; i++)
            for (int j = 0; j < k; j++) b[(size_t)i * k + j] = s[(size_t)j * f->n + i];
    } else {
        rc = tcb_fail(err, TCB_ERR_NOMEM, "cholesky: out of memory solving a %d × %d system", f->n, f->n);
    }
    cholmod_free_dense(&rhs, &c);
    cholmod_free_dense(&x, &c);
    cholmod_finish(&c);
    return rc;
}

int tcb_cholesky_order(const tcb_cholesky *f) { return f ? f->n : 0; }

void tcb_cholesky_free(tcb_cholesky *f)
{
    if (!f) return;
    cholmod_common c;
    start(&c);
    cholmod_free_factor(&f->factor, &c);
    cholmod_finish(&c);
    free(f);
}
