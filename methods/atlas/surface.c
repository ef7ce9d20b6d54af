/* The atlas's patches as one triangle mesh; see surface.h. */
#include "methods/atlas/surface.h"

#include <stdlib.h>

static void grid_faces(int P, int res, int32_t *faces)
{
    size_t f = 0;
    for (int p = 0; p < P; p++)
        for (int r = 0; r + 1 < res; r++)
            for (int c = 0; c + 1 < res; c++) {
                int32_t a = (int32_t)(((size_t)p * res + r) * res + c), b = a + 1, e = a + res, d = e + 1;
                /* (a, b, d) and (a, d, e): u grows to the right, v upwards, so both turn left. */
                int32_t t[6] = {a, b, d, a, d, e};
                for (int k = 0; k < 6; k++) faces[f * 3 + k] = t[k];
                f += 2;
            }
}

int tcb_atlas_uv_grid(int P, int res, tcb_uv_mesh *out, tcb_error *err)
{
    const tcb_uv_mesh none = {0, 0, 0, NULL, NULL, NULL, NULL};
    *out = none;
    if (P < 1 || res < 2 || (size_t)P * res * res > 100000000)
        return tcb_fail(err, TCB_ERR_INPUT, "atlas surface: %d patches of %d x %d vertices", P, res, res);
    size_t nv = (size_t)P * res * res, nf = (size_t)P * 2 * (res - 1) * (res - 1);
    out->uv = malloc(nv * 2 * sizeof *out->uv);
    out->chart = malloc(nv * sizeof *out->chart);
    out->faces = malloc(nf * 3 * sizeof *out->faces);
    if (!out->uv || !out->chart || !out->faces) {
        tcb_uv_mesh_free(out);
        return tcb_fail(err, TCB_ERR_NOMEM, "atlas surface: out of memory for %zu vertices", nv);
    }
    for (size_t k = 0; k < nv; k++) {
        int c = (int)(k % (size_t)res), r = (int)(k / (size_t)res % (size_t)res);
        out->chart[k] = (int32_t)(k / ((size_t)res * res));
        out->uv[2 * k] = (float)c / (float)(res - 1);
        out->uv[2 * k + 1] = (float)r / (float)(res - 1);
    }
    grid_faces(P, res, out->faces);
    out->n_verts = (int)nv, out->n_faces = (int)nf, out->n_charts = P;
    return TCB_OK;
}

int tcb_atlas_surface(const tcb_atlas_model *m, const float *cloud, int N, int res, tcb_uv_mesh *out,
                      tcb_error *err)
{
    int rc = tcb_atlas_uv_grid(m->P, res, out, err);
    tcb_atlas_work *w = NULL;
    /* The forward decodes samples [p M/P, (p+1) M/P) with patch p: the
     * grid's vertex order, so its uv array is the forward's input as is. */
    if (!rc) rc = tcb_atlas_work_create(m, 1, N, out->n_verts, &w, err);
    if (!rc && !(out->verts = malloc((size_t)out->n_verts * 3 * sizeof *out->verts)))
        rc = tcb_fail(err, TCB_ERR_NOMEM, "atlas surface: out of memory");
    if (!rc) tcb_atlas_model_forward(m, w, cloud, out->uv, out->verts, NULL, NULL);
    tcb_atlas_work_free(w);
    if (rc) tcb_uv_mesh_free(out);
    return rc;
}
