/* Test helper for tests/pytorch/atlas_net_check.py: runs one forward and
 * backward of a small atlas network on fixed random inputs and writes
 * everything PyTorch needs to redo it into DIR:
 *     weights.bin, weights.json   the model (tcb_atlas_model_export)
 *     case.json                   sizes and seed
 *     clouds.f32 [B][N][3], uv.f32 [M][2], coef_{phi,phi_u,phi_v}.f32 [B][M][3]
 *                                 inputs and the objective's weights
 *     phi.f32, phi_u.f32, phi_v.f32 [B][M][3], grads.f32 [nparams]
 *                                 C's outputs: the network and the gradient of
 *                                 L = Σ a·φ + Σ b·φ_u + Σ c·φ_v
 * (raw float32, see export.h).
 *
 * usage: atlas_export DIR */
#include <stdio.h>
#include <stdlib.h>

#include "methods/atlas/model.h"
#include "tests/pytorch/export.h"

enum { C = 64, P = 3, B = 3, N = 100, M = 30 };

static void fill(tcb_rng *r, float *x, size_t n, double lo, double hi)
{
    for (size_t i = 0; i < n; i++) x[i] = (float)(lo + (hi - lo) * tcb_rng_uniform(r));
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: atlas_export DIR\n");
        return 2;
    }
    const char *dir = argv[1];
    tcb_error err = {0};
    tcb_atlas_model *m;
    tcb_atlas_work *w;
    if (tcb_atlas_model_create(C, P, &m, &err) || tcb_atlas_work_create(m, B, N, M, &w, &err)) {
        fprintf(stderr, "atlas_export: %s\n", err.msg);
        return 1;
    }
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 2024, "tests/pytorch/atlas");
    tcb_atlas_model_init(m, &rng);
    static float clouds[B * N * 3], uv[M * 2], coef[3][B * M * 3], out[3][B * M * 3];
    fill(&rng, clouds, B * N * 3, -0.5, 0.5);
    /* the last shape is 4000x larger: its pre-activations cross softplus's
     * threshold (20), so both branches are compared with PyTorch */
    for (int i = (B - 1) * N * 3; i < B * N * 3; i++) clouds[i] *= 4000.0f;
    fill(&rng, uv, M * 2, 0, 1);
    for (int k = 0; k < 3; k++) fill(&rng, coef[k], B * M * 3, -1, 1);

    tcb_atlas_model_forward(m, w, clouds, uv, out[0], out[1], out[2]);
    tcb_atlas_model_zero_grad(m);
    if (tcb_atlas_model_backward(m, w, coef[0], coef[1], coef[2], &err)) {
        fprintf(stderr, "atlas_export: %s\n", err.msg);
        return 1;
    }

    if (export_model(m, dir, "weights", &err)) {
        fprintf(stderr, "atlas_export: %s\n", err.msg);
        return 1;
    }
    char json[EXPORT_PATH_MAX];
    FILE *fp = export_path(json, dir, "case.json") ? NULL : fopen(json, "w");
    if (!fp) return 1;
    fprintf(fp, "{\"C\": %d, \"P\": %d, \"B\": %d, \"N\": %d, \"M\": %d}\n", C, P, B, N, M);
    fclose(fp);
    int rc = export_f32(dir, "clouds.f32", clouds, B * N * 3) |
             export_f32(dir, "uv.f32", uv, M * 2) |
             export_f32(dir, "coef_phi.f32", coef[0], B * M * 3) |
             export_f32(dir, "coef_phi_u.f32", coef[1], B * M * 3) |
             export_f32(dir, "coef_phi_v.f32", coef[2], B * M * 3) |
             export_f32(dir, "phi.f32", out[0], B * M * 3) |
             export_f32(dir, "phi_u.f32", out[1], B * M * 3) |
             export_f32(dir, "phi_v.f32", out[2], B * M * 3) |
             export_f32(dir, "grads.f32", m->grads, m->nparams);
    tcb_atlas_work_free(w);
    tcb_atlas_model_free(m);
    return rc;
}
