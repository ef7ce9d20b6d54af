/* Test helper (not installed): one PDG training step's loss and gradients
 * (methods/pdg/train.c) on inputs written by tests/pytorch/pdg_step_check.py,
 * for comparison with its PyTorch autograd reference:
 *     pdg_step DIR LEVELS FRAMES KEY EPOCH EPOCHS WARMUP ROTATION
 * (ROTATION released or cayley: methods/pdg/field.h) reads DIR/verts.npy (float32 [nv][3], the template as it starts),
 * DIR/faces.npy (int32 [nf][3]), DIR/points_<t>.npy (float32 [n][3], in
 * the cube) and DIR/params.npy (float32: the fields' U, level-major
 * [T][r³][C], then the template's u), sets the trainer's epoch and parameters, runs one
 * step and writes DIR/c_loss.npy (float64 [total, input, pred, edge,
 * template]) and DIR/c_grads.npy (float32, the parameters' layout: the
 * gradient the step's Adam took). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "methods/pdg/field.h"

#include "methods/pdg/train.h"
#include "tcb/npy.h"

static int load_f32(const char *dir, const char *name, float **out, size_t *count, tcb_error *err)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    tcb_npy a;
    if (tcb_npy_load(path, &a, err)) return 1;
    double *x = malloc((size_t)a.count * sizeof *x + 1);
    *out = malloc((size_t)a.count * sizeof **out + 1);
    int rc = !x || !*out || tcb_npy_to_double(&a, x, err);
    for (size_t i = 0; !rc && i < a.count; i++) (*out)[i] = (float)x[i];
    *count = (size_t)a.count;
    free(x);
    tcb_npy_free(&a);
    return rc;
}

static int save(const char *dir, const char *name, tcb_npy_dtype t, uint64_t n, const void *data, tcb_error *err)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    return tcb_npy_save(path, t, 1, &n, data, err);
}

int main(int argc, char **argv)
{
    int rotation = 0;
    while (argc == 9 && tcb_pdg_rotation_names[rotation] && strcmp(argv[8], tcb_pdg_rotation_names[rotation]))
        rotation++;
    if (argc != 9 || !tcb_pdg_rotation_names[rotation]) {
        fprintf(stderr, "usage: pdg_step DIR LEVELS FRAMES KEY EPOCH EPOCHS WARMUP released|cayley\n");
        return 2;
    }
    const char *dir = argv[1];
    int levels = atoi(argv[2]), n = atoi(argv[3]), key = atoi(argv[4]);
    long long epoch = atoll(argv[5]), epochs = atoll(argv[6]), warmup = atoll(argv[7]);
    tcb_error err = {0};
    float *verts, *faces_f, *params, *pts[64];
    size_t nv3, nf3, np, cnt;
    int n_pts[64];
    tcb_nn *idx[64];
    if (n > 64 || load_f32(dir, "verts.npy", &verts, &nv3, &err) || load_f32(dir, "faces.npy", &faces_f, &nf3, &err) ||
        load_f32(dir, "params.npy", &params, &np, &err))
        goto fail;
    int32_t *faces = malloc(nf3 * sizeof *faces);
    for (size_t i = 0; i < nf3; i++) faces[i] = (int32_t)faces_f[i];
    for (int t = 0; t < n; t++) {
        char name[64];
        snprintf(name, sizeof name, "points_%d.npy", t);
        if (load_f32(dir, name, &pts[t], &cnt, &err)) goto fail;
        n_pts[t] = (int)(cnt / 3);
        if (tcb_nn_build(pts[t], n_pts[t], &idx[t], &err)) goto fail;
    }
    tcb_mesh tmpl = {(int)(nv3 / 3), (int)(nf3 / 3), verts, faces};
    tcb_pdg_data data = {n, key, (const float *const *)pts, n_pts, (const tcb_nn *const *)idx, &tmpl};
    tcb_pdg_arch a = tcb_pdg_arch_reference();
    a.levels = levels, a.rotation = (tcb_pdg_rotation)rotation;
    tcb_pdg_schedule s = {epochs, warmup, 0.005, 1.1, 1e-4, 0.0};
    tcb_pdg_trainer tr;
    if (tcb_pdg_trainer_init(&tr, &a, &s, &data, &err)) goto fail;
    if (np != tr.n_params) {
        tcb_fail(&err, TCB_ERR_INPUT, "params.npy: %zu values, the trainer has %zu", np, tr.n_params);
        goto fail;
    }
    memcpy(tr.params, params, np * sizeof *params);
    tr.it = epoch;
    double loss;
    if (tcb_pdg_train_step(&tr, &loss, &err)) goto fail;
    double l[5] = {tr.last.total, tr.last.input, tr.last.pred, tr.last.edge, tr.template_loss};
    if (save(dir, "c_loss.npy", TCB_NPY_F8, 5, l, &err) || save(dir, "c_grads.npy", TCB_NPY_F4, np, tr.grads, &err))
        goto fail;
    tcb_pdg_trainer_free(&tr);
    for (int t = 0; t < n; t++) free(pts[t]), tcb_nn_free(idx[t]);
    free(verts), free(faces_f), free(faces), free(params);
    return 0;
fail: /* a test helper: on failure the process ends at once */
    fprintf(stderr, "pdg_step: %s\n", err.msg);
    return 1;
}
