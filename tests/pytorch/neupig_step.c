/* Test helper (not installed): one Neu-PiG loss-and-gradient evaluation on
 * inputs written by tests/integration/test_neupig_pytorch.sh, for comparison
 * with its PyTorch autograd reference:
 *     neupig_step DIR LEVELS BASE_RES RES_STEP F NORMAL_RES FN J HIDDEN T KEY EPOCH EPOCHS
 * reads DIR/{verts,normals,edge_len,params}.npy (float32), DIR/edges.npy
 * (int32 [ne][2]), DIR/points_<t>.npy (float32 [n][3]) and writes
 * DIR/c_loss.npy (float64 [total, chamfer, edge]), DIR/c_cd.npy (float64
 * [T]) and DIR/c_grads.npy (float32, the parameters' layout). */
#include <stdio.h>
#include <stdlib.h>

#include "methods/neupig/model.h"
#include "tcb/npy.h"

/* The array DIR/name as doubles, checking its element count when want > 0. */
static double *load(const char *dir, const char *name, size_t want, size_t *count, tcb_error *err)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    tcb_npy a;
    if (tcb_npy_load(path, &a, err)) return NULL;
    double *x = malloc((size_t)a.count * sizeof *x + 1);
    if (!x || tcb_npy_to_double(&a, x, err) || (want && a.count != want)) {
        if (x && !err->msg[0]) tcb_fail(err, TCB_ERR_INPUT, "%s: %llu elements", path, (unsigned long long)a.count);
        free(x);
        tcb_npy_free(&a);
        return NULL;
    }
    *count = (size_t)a.count;
    tcb_npy_free(&a);
    return x;
}

static float *as_float(const double *x, size_t n)
{
    float *f = malloc(n * sizeof *f + 1);
    for (size_t i = 0; f && i < n; i++) f[i] = (float)x[i];
    return f;
}

static int save(const char *dir, const char *name, tcb_npy_dtype t, uint64_t n, const void *data, tcb_error *err)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    return tcb_npy_save(path, t, 1, &n, data, err);
}

int main(int argc, char **argv)
{
    if (argc != 14) {
        fprintf(stderr, "usage: neupig_step DIR LEVELS BASE_RES RES_STEP F NORMAL_RES FN J HIDDEN T KEY EPOCH EPOCHS\n");
        return 2;
    }
    const char *dir = argv[1];
    int v[12];
    for (int i = 0; i < 12; i++) v[i] = atoi(argv[2 + i]);
    tcb_neupig_arch a = tcb_neupig_arch_reference();
    a.levels = v[0], a.base_res = v[1], a.res_step = v[2], a.features = v[3];
    a.normal_res = v[4], a.normal_features = v[5], a.time_freqs = v[6], a.hidden = v[7];
    int T = v[8];
    tcb_error err = {0};
    tcb_neupig_model m;
    if (tcb_neupig_model_init(&m, &a, &err)) goto fail;
    size_t nv3, nn3, ne2, ne, np;
    double *verts = load(dir, "verts.npy", 0, &nv3, &err), *normals = verts ? load(dir, "normals.npy", nv3, &nn3, &err) : NULL;
    double *edges = normals ? load(dir, "edges.npy", 0, &ne2, &err) : NULL;
    double *len = edges ? load(dir, "edge_len.npy", ne2 / 2, &ne, &err) : NULL;
    double *params = len ? load(dir, "params.npy", m.n_params, &np, &err) : NULL;
    if (!params) goto fail;
    int32_t *e32 = malloc(ne2 * sizeof *e32);
    for (size_t i = 0; i < ne2; i++) e32[i] = (int32_t)edges[i];
    float *pts[64];
    int n_pts[64];
    tcb_nn *idx[64];
    for (int t = 0; t < T && t < 64; t++) {
        char name[64];
        size_t n;
        snprintf(name, sizeof name, "points_%d.npy", t);
        double *p = load(dir, name, 0, &n, &err);
        if (!p) goto fail;
        pts[t] = as_float(p, n), n_pts[t] = (int)(n / 3);
        free(p);
        if (tcb_nn_build(pts[t], n_pts[t], &idx[t], &err)) goto fail;
    }
    float *vf = as_float(verts, nv3), *nf = as_float(normals, nn3), *lf = as_float(len, ne);
    float *pf = as_float(params, np), *grads = malloc(np * sizeof *grads);
    tcb_neupig_problem prob = {(int)(nv3 / 3), vf, nf, (int)ne, e32, lf, T,
                               (const float *const *)pts, n_pts, (const tcb_nn *const *)idx, v[9]};
    tcb_neupig_loss loss;
    tcb_neupig_work work;
    if (tcb_neupig_work_init(&work, &m, &prob, &err) ||
        tcb_neupig_loss_grad(&m, pf, &prob, &work, v[10], v[11], &loss, grads, &err))
        goto fail;
    const double *cd = work.cd;
    double l[3] = {loss.total, loss.chamfer, loss.edge};
    if (save(dir, "c_loss.npy", TCB_NPY_F8, 3, l, &err) || save(dir, "c_cd.npy", TCB_NPY_F8, (uint64_t)T, cd, &err) ||
        save(dir, "c_grads.npy", TCB_NPY_F4, np, grads, &err))
        goto fail;
    for (int t = 0; t < T; t++) free(pts[t]), tcb_nn_free(idx[t]);
    free(verts), free(normals), free(edges), free(len), free(params), free(e32);
    free(vf), free(nf), free(lf), free(pf), free(grads);
    tcb_neupig_work_free(&work);
    tcb_neupig_model_free(&m);
    return 0;
fail: /* a test helper: on failure the process ends at once */
    fprintf(stderr, "neupig_step: %s\n", err.msg);
    return 1;
}
