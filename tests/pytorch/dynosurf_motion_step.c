/* Helper of dynosurf_motion_check.py: one step of DynoSurf's stage 2
 * (methods/dynosurf/motion.c) on F frames of an ellipsoid turning and
 * moving (points with normals), the template the convex hull of frame 0's
 * points, a grid of random points with random SDF values, keyframe 1; the
 * loss's five terms, the deformer's gradient and Adam's first step
 * (lr 1e-4), and the gradient of each term alone (its reference weight,
 * the others 0, the same picks and draws: the rng restarts from the same
 * state). Writes into DIR (float32 / int32, host order):
 *   params.bin [P]  tv.bin [m][3]  tf.bin [nf][3] (int32)
 *   pts.bin, nrm.bin [F][n][3]  y.bin [g][3]  yhat.bin [g]
 *   draw_face.bin [F][ms] (int32)  draw_w.bin [F][ms][3]  grad.bin [P]  after.bin [P]
 *   grad_TERM.bin [P] for TERM in chamfer normal identity sdf_sign smooth
 *   meta.json {P, K, F, n, m, nf, g, ms, key, blend_offset, chamfer, normal,
 *              identity, sdf_sign, smooth, total}
 * usage: dynosurf_motion_step SEED DIR */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "methods/dynosurf/motion.h"
#include "neural/adam.h"
#include "tcb/meshing.h"
#include "tcb/rng.h"
#include "tests/pytorch/export.h"

enum { F = 4, N = 800, NG = 3000, G = 1000, MS = 2000, KEY = 1 };

static int fail(const tcb_error *err)
{
    fprintf(stderr, "dynosurf_motion_step: %s\n", err->msg);
    return 1;
}

/* frame t: the ellipsoid (0.3, 0.2, 0.15) turned by 0.15 t about z and
 * moved by 0.02 t along x, with its unit normals */
static void frame(tcb_rng *rng, int t, float *p, float *nrm)
{
    const double ax[3] = {0.3, 0.2, 0.15}, a = 0.15 * t, c = cos(a), s = sin(a);
    for (int i = 0; i < N; i++) {
        double u[3] = {tcb_rng_normal(rng), tcb_rng_normal(rng), tcb_rng_normal(rng)};
        double len = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]), q[3], g[3], gl = 0;
        for (int k = 0; k < 3; k++) q[k] = ax[k] * u[k] / len, g[k] = u[k] / len / ax[k], gl += g[k] * g[k];
        gl = sqrt(gl);
        p[3 * i] = (float)(c * q[0] - s * q[1] + 0.02 * t), p[3 * i + 1] = (float)(s * q[0] + c * q[1]);
        p[3 * i + 2] = (float)q[2];
        nrm[3 * i] = (float)((c * g[0] - s * g[1]) / gl), nrm[3 * i + 1] = (float)((s * g[0] + c * g[1]) / gl);
        nrm[3 * i + 2] = (float)(g[2] / gl);
    }
}

int main(int argc, char **argv)
{
    if (argc != 3) {
        fprintf(stderr, "usage: dynosurf_motion_step SEED DIR\n");
        return 2;
    }
    const char *dir = argv[2];
    tcb_rng rng;
    tcb_rng_seed(&rng, (uint64_t)atoll(argv[1]));
    tcb_error err = {0};
    float *pts = malloc(F * N * 3 * sizeof *pts), *nrm = malloc(F * N * 3 * sizeof *nrm);
    const float *pp[F], *np[F];
    int n_pts[F];
    tcb_nn *index[F];
    for (int t = 0; t < F; t++) {
        frame(&rng, t, pts + 3 * N * t, nrm + 3 * N * t);
        pp[t] = pts + 3 * N * t, np[t] = nrm + 3 * N * t, n_pts[t] = N;
        if (tcb_nn_build(pp[t], N, &index[t], &err)) return fail(&err);
    }
    tcb_mesh hull;
    if (tcb_convex_hull(pts, N, &hull, &err)) return fail(&err);
    float *gv = malloc(NG * 3 * sizeof *gv), *gs = malloc(NG * sizeof *gs);
    for (int i = 0; i < 3 * NG; i++) gv[i] = (float)(0.8 * (tcb_rng_uniform(&rng) - 0.5));
    for (int i = 0; i < NG; i++) gs[i] = (float)(0.05 * tcb_rng_normal(&rng));
    size_t P = dyno_deformer_size();
    float *params = malloc(P * sizeof *params), *grad = calloc(P, sizeof *grad);
    dyno_deformer d, g;
    dyno_deformer_bind(&d, params), dyno_deformer_bind(&g, grad);
    if (dyno_deformer_init(&d, gv, NG, &rng, &err)) return fail(&err);
    dyno_motion_data data = {.n_frames = F, .key = KEY, .pts = pp, .normals = np, .n_pts = n_pts,
                             .index = (const tcb_nn *const *)index, .template_verts = hull.verts,
                             .n_template = hull.n_verts, .faces = hull.faces, .n_faces = hull.n_faces,
                             .grid_v = gv, .grid_sdf = gs, .n_grid = NG, .n_samples = MS, .n_grid_samples = G,
                             .weights = DYNO_MOTION_WEIGHTS};
    dyno_motion_fit fit;
    if (dyno_motion_fit_init(&fit, &data, &err)) return fail(&err);
    int rc = export_f32(dir, "params.bin", params, P);
    dyno_motion_terms t;
    static const char *names[5] = {"grad_chamfer.bin", "grad_normal.bin", "grad_identity.bin", "grad_sdf_sign.bin",
                                   "grad_smooth.bin"};
    const dyno_motion_weights full = DYNO_MOTION_WEIGHTS, alone[5] = {
        {full.chamfer, 0, 0, 0, 0}, {0, full.normal, 0, 0, 0}, {0, 0, full.identity, 0, 0},
        {0, 0, 0, full.sdf_sign, 0}, {0, 0, 0, 0, full.smooth}};
    for (int term = 0; term < 5; term++) {
        tcb_rng again = rng;
        fit.data.weights = alone[term];
        memset(grad, 0, P * sizeof *grad);
        if (dyno_motion_loss(&fit, &d, &g, &again, &t, &err)) return fail(&err);
        rc |= export_f32(dir, names[term], grad, P);
    }
    fit.data.weights = full;
    memset(grad, 0, P * sizeof *grad);
    if (dyno_motion_loss(&fit, &d, &g, &rng, &t, &err)) return fail(&err);
    int32_t *face = malloc(F * MS * sizeof *face);
    float *w = malloc(F * MS * 3 * sizeof *w);
    for (int i = 0; i < F * MS; i++) face[i] = fit.draws[i].face, memcpy(w + 3 * i, fit.draws[i].w, 3 * sizeof *w);
    tcb_adam adam;
    if (tcb_adam_init(&adam, P, &err)) return fail(&err);
    tcb_adam_step(&adam, params, grad, 1e-4);
    rc |= export_f32(dir, "tv.bin", hull.verts, (size_t)hull.n_verts * 3) |
          export_raw(dir, "tf.bin", hull.faces, sizeof(int32_t), (size_t)hull.n_faces * 3) |
          export_f32(dir, "pts.bin", pts, F * N * 3) | export_f32(dir, "nrm.bin", nrm, F * N * 3) |
          export_f32(dir, "y.bin", fit.y, G * 3) | export_f32(dir, "yhat.bin", fit.yhat, G) |
          export_raw(dir, "draw_face.bin", face, sizeof(int32_t), F * MS) | export_f32(dir, "draw_w.bin", w, F * MS * 3) |
          export_f32(dir, "grad.bin", grad, P) | export_f32(dir, "after.bin", params, P);
    char path[EXPORT_PATH_MAX];
    rc |= export_path(path, dir, "meta.json");
    FILE *fp = rc ? NULL : fopen(path, "w");
    if (!fp) return 1;
    fprintf(fp,
            "{\"P\": %zu, \"K\": %d, \"F\": %d, \"n\": %d, \"m\": %d, \"nf\": %d, \"g\": %d, \"ms\": %d, \"key\": %d, "
            "\"blend_offset\": %zu, \"chamfer\": %.17g, \"normal\": %.17g, \"identity\": %.17g, \"sdf_sign\": %.17g, "
            "\"smooth\": %.17g, \"total\": %.17g}\n",
            P, DYNO_CONTROL_POINTS, F, N, hull.n_verts, hull.n_faces, G, MS, KEY, dyno_deformer_blend_offset(),
            t.chamfer, t.normal, t.identity, t.sdf_sign, t.smooth, t.total);
    rc |= fclose(fp) != 0;
    dyno_motion_fit_free(&fit);
    tcb_adam_free(&adam);
    for (int u = 0; u < F; u++) tcb_nn_free(index[u]);
    tcb_mesh_free(&hull);
    free(pts), free(nrm), free(gv), free(gs), free(params), free(grad), free(face), free(w);
    return rc;
}
