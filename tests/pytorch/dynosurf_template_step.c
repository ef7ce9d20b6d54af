/* Helper of dynosurf_template_check.py: DynoSurf's template objectives
 * (methods/dynosurf/template.c) on an ellipsoid's points and normals, on
 * the grid dyno_grid_build makes around them (its shell remeshed to 4 % of
 * its diagonal: a test-sized grid). The network is first brought
 * near the hull's signed distance (PRE Adam steps of the pretraining at
 * lr 1e-3) so that its zero set crosses the grid; then, from those
 * weights, one pretraining loss and one stage-1 loss with its draws, and
 * the Adam step of stage 1 (lr 1e-4, a fresh optimiser). Writes into DIR
 * (float32 / int32, host order):
 *   grid_x.bin [nv][3]  grid_t.bin [nt][4] (int32)  pts.bin, nrm.bin [n][3]
 *   target.bin [nv]  params.bin [P]  pre_grad.bin [P]
 *   draw_face.bin [m] (int32)  draw_w.bin [m][3]  grad.bin [P]  after.bin [P]
 *   grad_TERM.bin [P], TERM in chamfer normal sdf: each term alone
 *   meta.json {nv, nt, n, m, P, edge, pre_loss, chamfer, normal, sdf, total,
 *              n_verts, n_faces}
 * usage: dynosurf_template_step N M PRE SEED DIR */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "methods/dynosurf/grid.h"
#include "methods/dynosurf/template.h"
#include "neural/adam.h"
#include "tcb/meshing.h"
#include "tcb/rng.h"
#include "tests/pytorch/export.h"

static int fail(const tcb_error *err)
{
    fprintf(stderr, "dynosurf_template_step: %s\n", err->msg);
    return 1;
}

/* n points on the ellipsoid with semi-axes 0.3, 0.2, 0.15 and their unit normals. */
static void ellipsoid(tcb_rng *rng, int n, float *p, float *nrm)
{
    const double ax[3] = {0.3, 0.2, 0.15};
    for (int i = 0; i < n; i++) {
        double u[3] = {tcb_rng_normal(rng), tcb_rng_normal(rng), tcb_rng_normal(rng)}, len = 0, nl = 0, g[3];
        for (int c = 0; c < 3; c++) len += u[c] * u[c];
        len = sqrt(len);
        for (int c = 0; c < 3; c++) {
            p[3 * i + c] = (float)(ax[c] * u[c] / len);
            g[c] = u[c] / len / ax[c];
            nl += g[c] * g[c];
        }
        for (int c = 0; c < 3; c++) nrm[3 * i + c] = (float)(g[c] / sqrt(nl));
    }
}

int main(int argc, char **argv)
{
    if (argc != 6) {
        fprintf(stderr, "usage: dynosurf_template_step N M PRE SEED DIR\n");
        return 2;
    }
    int n = atoi(argv[1]), m = atoi(argv[2]), pre = atoi(argv[3]);
    const char *dir = argv[5];
    tcb_rng rng;
    tcb_rng_seed(&rng, (uint64_t)atoll(argv[4]));
    tcb_error err = {0};
    float *pts = malloc((size_t)n * 3 * sizeof *pts), *nrm = malloc((size_t)n * 3 * sizeof *nrm);
    ellipsoid(&rng, n, pts, nrm);
    tcb_mesh hull, shell;
    tcb_tetmesh grid;
    if (dyno_grid_build(pts, n, 1e-4, 0.04, &hull, &shell, &grid, &err)) return fail(&err);
    float *target = malloc((size_t)grid.n_verts * sizeof *target);
    if (tcb_convex_signed_distance(&hull, grid.verts, grid.n_verts, target, &err)) return fail(&err);
    float edge = (float)dyno_tet_edge_bound(&grid);
    tcb_nn *index;
    if (tcb_nn_build(pts, n, &index, &err)) return fail(&err);
    dyno_template_fit fit;
    if (dyno_template_fit_init(&fit, &grid, edge, pts, nrm, n, index, m, &err)) return fail(&err);

    size_t P = dyno_shape_size();
    float *params = malloc(P * sizeof *params), *pre_grad = calloc(P, sizeof *pre_grad),
          *grad = calloc(P, sizeof *grad);
    dyno_shape s, g_pre, g;
    dyno_shape_bind(&s, params), dyno_shape_bind(&g_pre, pre_grad), dyno_shape_bind(&g, grad);
    dyno_shape_init(&s, &rng);
    tcb_adam adam;
    if (tcb_adam_init(&adam, P, &err)) return fail(&err);
    for (int it = 0; it < pre; it++) {
        memset(pre_grad, 0, P * sizeof *pre_grad);
        dyno_pretrain_loss(&fit, &s, &g_pre, target);
        tcb_adam_step(&adam, params, pre_grad, 1e-3);
    }
    memset(pre_grad, 0, P * sizeof *pre_grad);
    double pre_loss = dyno_pretrain_loss(&fit, &s, &g_pre, target);
    int rc = export_f32(dir, "params.bin", params, P) | export_f32(dir, "pre_grad.bin", pre_grad, P);

    dyno_template_terms t;
    const dyno_template_weights full = DYNO_TEMPLATE_WEIGHTS,
                                alone[3] = {{full.chamfer, 0, 0}, {0, full.normal, 0}, {0, 0, full.sdf}};
    static const char *names[3] = {"grad_chamfer.bin", "grad_normal.bin", "grad_sdf.bin"};
    for (int term = 0; term < 3; term++) { /* each term alone, on the same draws */
        tcb_rng again = rng;
        fit.weights = alone[term];
        memset(grad, 0, P * sizeof *grad);
        if (dyno_template_loss(&fit, &s, &g, &again, &t, &err)) return fail(&err);
        rc |= export_f32(dir, names[term], grad, P);
    }
    fit.weights = full;
    memset(grad, 0, P * sizeof *grad);
    if (dyno_template_loss(&fit, &s, &g, &rng, &t, &err)) return fail(&err);
    int32_t *face = malloc((size_t)m * sizeof *face);
    float *w = malloc((size_t)m * 3 * sizeof *w);
    for (int i = 0; i < m; i++) {
        face[i] = fit.draws[i].face;
        memcpy(w + 3 * i, fit.draws[i].w, sizeof fit.draws[i].w);
    }
    tcb_adam_reset(&adam);
    tcb_adam_step(&adam, params, grad, 1e-4);
    rc |= export_f32(dir, "grid_x.bin", grid.verts, (size_t)grid.n_verts * 3) |
          export_raw(dir, "grid_t.bin", grid.tets, sizeof(int32_t), (size_t)grid.n_tets * 4) |
          export_f32(dir, "pts.bin", pts, (size_t)n * 3) | export_f32(dir, "nrm.bin", nrm, (size_t)n * 3) |
          export_f32(dir, "target.bin", target, (size_t)grid.n_verts) |
          export_raw(dir, "draw_face.bin", face, sizeof(int32_t), (size_t)m) |
          export_f32(dir, "draw_w.bin", w, (size_t)m * 3) | export_f32(dir, "grad.bin", grad, P) |
          export_f32(dir, "after.bin", params, P);
    char path[EXPORT_PATH_MAX];
    rc |= export_path(path, dir, "meta.json");
    FILE *fp = rc ? NULL : fopen(path, "w");
    if (!fp) return 1;
    fprintf(fp,
            "{\"nv\": %d, \"nt\": %d, \"n\": %d, \"m\": %d, \"P\": %zu, \"edge\": %.9g, \"pre_loss\": %.17g, "
            "\"chamfer\": %.17g, \"normal\": %.17g, \"sdf\": %.17g, \"total\": %.17g, \"n_verts\": %d, "
            "\"n_faces\": %d}\n",
            grid.n_verts, grid.n_tets, n, m, P, edge, pre_loss, t.chamfer, t.normal, t.sdf, t.total, t.n_verts,
            t.n_faces);
    rc |= fclose(fp) != 0;
    dyno_template_fit_free(&fit);
    tcb_adam_free(&adam);
    tcb_nn_free(index);
    tcb_mesh_free(&hull), tcb_mesh_free(&shell), tcb_tetmesh_free(&grid);
    free(pts), free(nrm), free(target), free(params), free(pre_grad), free(grad), free(face), free(w);
    return rc;
}
