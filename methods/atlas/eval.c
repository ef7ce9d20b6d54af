#include "methods/atlas/eval.h"

#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "methods/atlas/collapse.h"

/* The regular set of m points repeated for each of the P patches: [P·m][2]. */
static int tiled_uv(tcb_atlas_uv_cache *uvc, int m, int P, float **out, tcb_error *err)
{
    const float *uv;
    int rc = tcb_atlas_uv_cache_get(uvc, m, &uv, err);
    if (rc) return rc;
    *out = malloc((size_t)P * m * 2 * sizeof **out);
    if (!*out) return tcb_fail(err, TCB_ERR_NOMEM, "atlas: out of memory for UV samples");
    for (int p = 0; p < P; p++) memcpy(*out + (size_t)p * m * 2, uv, (size_t)m * 2 * sizeof *uv);
    return TCB_OK;
}

void tcb_atlas_eval_state_init(tcb_atlas_eval_state *s, uint64_t seed)
{
    *s = (tcb_atlas_eval_state){0};
    tcb_atlas_uv_cache_init(&s->uvc, seed);
}

void tcb_atlas_eval_state_free(tcb_atlas_eval_state *s)
{
    tcb_atlas_uv_cache_free(&s->uvc);
    for (int k = 0; k < 2; k++) tcb_atlas_work_free(s->work[k]);
    s->work[0] = s->work[1] = NULL;
}

/* s->work[pass] sized for two clouds of N points decoded at M samples with
 * the current thread count (a workspace has scratch for its threads only). */
static int work_for(const tcb_atlas_model *m, tcb_atlas_eval_state *s, int pass, int N, int M, tcb_error *err)
{
    tcb_atlas_work *w = s->work[pass];
    int threads = omp_get_max_threads() < m->P ? omp_get_max_threads() : m->P;
    if (w && w->P == m->P && w->N == N && w->M == M && w->nthreads == threads) return TCB_OK;
    tcb_atlas_work_free(w);
    s->work[pass] = NULL;
    return tcb_atlas_work_create(m, 2, N, M, &s->work[pass], err);
}

/* phi_u == NULL: values only (the second pass). phi, phi_u, phi_v [2][P·m][3]. */
static int decode(const tcb_atlas_model *m, tcb_atlas_eval_state *s, const float *clouds, int N,
                  int per_patch, float *phi, float *phi_u, float *phi_v, tcb_error *err)
{
    float *uv = NULL;
    int pass = phi_u ? 0 : 1;
    int rc = tiled_uv(&s->uvc, per_patch, m->P, &uv, err);
    if (!rc) rc = work_for(m, s, pass, N, m->P * per_patch, err);
    if (!rc) tcb_atlas_model_forward(m, s->work[pass], clouds, uv, phi, phi_u, phi_v);
    free(uv);
    return rc;
}

static int kept_patches(const tcb_atlas_model *m, tcb_atlas_eval_state *s, const float *clouds,
                        int N, int *kept, int *n_kept, int *m2, tcb_error *err)
{
    int m1 = TCB_ATLAS_EVAL_POINTS / m->P, M = m1 * m->P;
    size_t len = (size_t)2 * M * 3;
    float *buf = malloc(3 * len * sizeof *buf);
    if (!buf) return tcb_fail(err, TCB_ERR_NOMEM, "atlas: out of memory for the first pass");
    int rc = decode(m, s, clouds, N, m1, buf, buf + len, buf + 2 * len, err);
    if (!rc)
        rc = tcb_atlas_kept_patches(buf + len, buf + 2 * len, 2, M, m->P, TCB_ATLAS_EVAL_POINTS, kept,
                                    n_kept, m2, err);
    free(buf);
    return rc;
}

int tcb_atlas_eval_pair(const tcb_atlas_model *m, tcb_atlas_eval_state *s, const float *clouds,
                        int N, float **pred, int *n, tcb_error *err)
{
    *pred = NULL, *n = 0;
    int P = m->P, n_kept = 0, m2 = 0;
    int *kept = malloc((size_t)P * sizeof *kept);
    if (!kept) return tcb_fail(err, TCB_ERR_NOMEM, "atlas: out of memory");
    int rc = kept_patches(m, s, clouds, N, kept, &n_kept, &m2, err);
    size_t M2 = (size_t)P * m2, out_n = (size_t)n_kept * m2;
    float *phi = rc ? NULL : malloc((size_t)2 * M2 * 3 * sizeof *phi);
    float *out = rc ? NULL : malloc(2 * out_n * 3 * sizeof *out);
    if (!rc && (!phi || !out)) rc = tcb_fail(err, TCB_ERR_NOMEM, "atlas: out of memory for the second pass");
    if (!rc) rc = decode(m, s, clouds, N, m2, phi, NULL, NULL, err);
    for (int s = 0; !rc && s < 2; s++)
        for (int k = 0; k < n_kept; k++)
            memcpy(out + ((size_t)s * out_n + (size_t)k * m2) * 3,
                   phi + ((size_t)s * M2 + (size_t)kept[k] * m2) * 3, (size_t)m2 * 3 * sizeof *out);
    free(kept), free(phi);
    if (rc) {
        free(out);
        return rc;
    }
    *pred = out, *n = (int)out_n;
    return TCB_OK;
}
