/* Test helper (not installed): marching tetrahedra on TetGen's grid of the
 * unit cube, forward and backward, with what an independent reference needs
 * to redo both:
 *     marching_tets_dump MAX_VOLUME SEED OUT_DIR
 * The values are a sphere's signed distance (radius 0.35 about the cube's
 * centre, positive outside) plus seeded noise; the upstream gradient is
 * seeded too. Writes to OUT_DIR, little-endian:
 *     x.bin      float32 [nv][3]  grid positions
 *     s.bin      float32 [nv]     values
 *     tets.bin   int32   [nt][4]
 *     verts.bin  float32 [n][3]   the surface's vertices
 *     faces.bin  int32   [m][3]
 *     g.bin      float32 [n][3]   an upstream gradient
 *     dx.bin     float32 [nv][3]  backward: into the positions
 *     ds.bin     float32 [nv]     backward: into the values
 *     meta.json  {"nv", "nt", "n", "m"}
 * (tests/integration/test_marching_tets_torch.sh redoes them as kaolin does
 * in PyTorch). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "neural/marching_tets.h"
#include "tcb/rng.h"
#include "tcb/tetmesh.h"
#include "write_bin.h"

static tcb_mesh unit_cube(void)
{
    static const float v[24] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1};
    static const int32_t f[36] = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
                                  1, 2, 6, 1, 6, 5, 2, 3, 7, 2, 7, 6, 3, 0, 4, 3, 4, 7};
    return (tcb_mesh){8, 12, (float *)v, (int32_t *)f};
}

static int write_meta(const char *dir, const tcb_tetmesh *g, const tcb_mt_surface *m, tcb_error *err)
{
    char path[TCB_PATH_MAX];
    int rc = tcb_path_join(path, sizeof path, err, "%s/meta.json", dir);
    if (rc) return rc;
    FILE *f = fopen(path, "w");
    if (!f) return tcb_fail(err, TCB_ERR_IO, "%s: cannot write", path);
    fprintf(f, "{\"nv\": %d, \"nt\": %d, \"n\": %d, \"m\": %d}\n", g->n_verts, g->n_tets, m->n_verts, m->n_faces);
    return fclose(f) ? tcb_fail(err, TCB_ERR_IO, "%s: cannot write", path) : TCB_OK;
}

int main(int argc, char **argv)
{
    if (argc != 4) {
        fprintf(stderr, "usage: marching_tets_dump MAX_VOLUME SEED OUT_DIR\n");
        return 2;
    }
    const char *dir = argv[3];
    tcb_error err = {0};
    tcb_mesh shell = unit_cube();
    tcb_tetmesh g;
    tcb_mt_surface m = {0};
    float *s = NULL, *gr = NULL, *dx = NULL, *ds = NULL;
    int rc = tcb_tetrahedralize(&shell, atof(argv[1]), 2.0, &g, &err);
    if (rc) goto done;
    tcb_rng rng;
    tcb_rng_seed(&rng, (uint64_t)atoll(argv[2]));
    s = malloc((size_t)g.n_verts * sizeof *s);
    for (int i = 0; i < g.n_verts; i++) {
        double d2 = 0;
        for (int k = 0; k < 3; k++) d2 += (g.verts[3 * i + k] - 0.5) * (g.verts[3 * i + k] - 0.5);
        s[i] = (float)(sqrt(d2) - 0.35 + 0.02 * tcb_rng_normal(&rng));
    }
    if ((rc = tcb_marching_tets_forward(g.verts, s, g.n_verts, g.tets, g.n_tets, &m, &err))) goto done;
    gr = malloc(((size_t)m.n_verts * 3 + 1) * sizeof *gr);
    dx = calloc((size_t)g.n_verts * 3, sizeof *dx);
    ds = calloc((size_t)g.n_verts, sizeof *ds);
    for (int i = 0; i < 3 * m.n_verts; i++) gr[i] = (float)tcb_rng_normal(&rng);
    tcb_marching_tets_backward(g.verts, s, &m, gr, dx, ds);
    rc = tcb_test_write_bin(dir, "x.bin", g.verts, (size_t)g.n_verts * 3 * sizeof(float), &err);
    if (!rc) rc = tcb_test_write_bin(dir, "s.bin", s, (size_t)g.n_verts * sizeof(float), &err);
    if (!rc) rc = tcb_test_write_bin(dir, "tets.bin", g.tets, (size_t)g.n_tets * 4 * sizeof(int32_t), &err);
    if (!rc) rc = tcb_test_write_bin(dir, "verts.bin", m.verts, (size_t)m.n_verts * 3 * sizeof(float), &err);
    if (!rc) rc = tcb_test_write_bin(dir, "faces.bin", m.faces, (size_t)m.n_faces * 3 * sizeof(int32_t), &err);
    if (!rc) rc = tcb_test_write_bin(dir, "g.bin", gr, (size_t)m.n_verts * 3 * sizeof(float), &err);
    if (!rc) rc = tcb_test_write_bin(dir, "dx.bin", dx, (size_t)g.n_verts * 3 * sizeof(float), &err);
    if (!rc) rc = tcb_test_write_bin(dir, "ds.bin", ds, (size_t)g.n_verts * sizeof(float), &err);
    if (!rc) rc = write_meta(dir, &g, &m, &err);
done:
    if (rc) fprintf(stderr, "marching_tets_dump: %s\n", err.msg);
    tcb_mt_surface_free(&m);
    if (g.verts || g.tets) tcb_tetmesh_free(&g);
    free(s), free(gr), free(dx), free(ds);
    return rc ? 1 : 0;
}
