/* DynoSurf's frame, keyframe and grid (methods/dynosurf/grid.h). */
#include "methods/dynosurf/grid.h"

#include <math.h>
#include <stdlib.h>

#include "methods/pcgrid/prepare.h"
#include "tcb/geometry.h"
#include "tcb/meshing.h"
#include "tcb/nn.h"

int dyno_frame_of(const float *pts0, int n, dyno_frame *f, tcb_error *err)
{
    if (n < 1) return tcb_fail(err, TCB_ERR_INPUT, "dynosurf: frame 0 has no point");
    if (!tcb_all_finite(pts0, (size_t)3 * n))
        return tcb_fail(err, TCB_ERR_NUMERIC, "dynosurf: a point of frame 0 is not finite");
    double box[6];
    tcb_bbox(pts0, (size_t)n, box);
    f->diag = tcb_bbox_diag(box);
    if (!(f->diag > 0)) return tcb_fail(err, TCB_ERR_INPUT, "dynosurf: every point of frame 0 is the same");
    for (int k = 0; k < 3; k++) {
        double s = 0;
        for (int i = 0; i < n; i++) s += pts0[3 * (size_t)i + k];
        f->mean[k] = s / n;
    }
    return TCB_OK;
}

int dyno_frame_map(const float *const *clouds, const int *n, int T, struct tcb_pcgrid_frame_map *map, tcb_error *err)
{
    dyno_frame f;
    int rc = T > 0 ? dyno_frame_of(clouds[0], n[0], &f, err) : tcb_fail(err, TCB_ERR_INPUT, "dynosurf: no frame");
    if (rc) return rc;
    for (int k = 0; k < 3; k++) map->centre[k] = f.mean[k];
    map->scale = 1.0 / f.diag;
    return TCB_OK;
}

void dyno_map_points(const dyno_frame *f, const float *pts, int n, float *out)
{
    for (size_t i = 0; i < (size_t)n; i++)
        for (int k = 0; k < 3; k++) out[3 * i + k] = (float)((pts[3 * i + k] - f->mean[k]) / f->diag);
}

/* Σ over a's points of the squared distance to the nearest of b's. */
static int nearest_sum(const tcb_nn *b, const float *a, int na, int32_t *idx, float *d2, double *sum,
                       tcb_error *err)
{
    int rc = tcb_nn_query1(b, a, na, idx, d2, err);
    double s = 0;
    for (int i = 0; !rc && i < na; i++) s += d2[i];
    *sum = s;
    return rc;
}

int dyno_keyframe(const float *const *points, const int *n, int T, int *key, tcb_error *err)
{
    int most = 0;
    for (int t = 0; t < T; t++) most = n[t] > most ? n[t] : most;
    tcb_nn **index = calloc((size_t)T, sizeof *index);
    double *one_way = malloc((size_t)T * T * sizeof *one_way); /* [t][u]: Σ_{p ∈ P_t} min_{q ∈ P_u} */
    int32_t *idx = malloc((size_t)(most ? most : 1) * sizeof *idx);
    float *d2 = malloc((size_t)(most ? most : 1) * sizeof *d2);
    int rc = index && one_way && idx && d2 ? TCB_OK : tcb_fail(err, TCB_ERR_NOMEM, "dynosurf: out of memory");
    for (int t = 0; !rc && t < T; t++) rc = tcb_nn_build(points[t], n[t], &index[t], err);
    for (int t = 0; !rc && t < T; t++)
        for (int u = 0; !rc && u < T; u++)
            rc = t == u ? (one_way[t * T + u] = 0, TCB_OK)
                        : nearest_sum(index[u], points[t], n[t], idx, d2, &one_way[t * T + u], err);
    double best = INFINITY;
    for (int t = 0; !rc && t < T; t++) {
        double mean = 0;
        for (int u = 0; u < T; u++) mean += (one_way[t * T + u] + one_way[u * T + t]) / T;
        if (mean < best) best = mean, *key = t;
    }
    for (int t = 0; index && t < T; t++) tcb_nn_free(index[t]);
    free(index), free(one_way), free(idx), free(d2);
    return rc;
}

int dyno_grid_build(const float *pts, int n, double max_volume, double remesh, tcb_mesh *hull, tcb_mesh *shell,
                    tcb_tetmesh *grid, tcb_error *err)
{
    tcb_mesh grown = {0};
    *shell = (tcb_mesh){0};
    int rc = tcb_convex_hull(pts, n, hull, err);
    if (!rc) rc = tcb_convex_offset(pts, n, DYNO_SHELL_OFFSET, &grown, err);
    if (!rc) {
        double box[6];
        tcb_bbox(grown.verts, (size_t)grown.n_verts, box);
        rc = tcb_mesh_remesh(&grown, remesh * tcb_bbox_diag(box), DYNO_REMESH_ITERATIONS, shell, err);
    }
    if (!rc) rc = tcb_tetrahedralize(shell, max_volume, DYNO_TET_RADIUS_EDGE, grid, err);
    tcb_mesh_free(&grown);
    if (rc) {
        tcb_mesh_free(hull);
        tcb_mesh_free(shell);
        tcb_error_prefix(err, "dynosurf: the grid: ");
    }
    return rc;
}

double dyno_tet_edge_bound(const tcb_tetmesh *grid)
{
    static const int pairs[6][2] = {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {0, 2}, {1, 3}};
    double shortest = INFINITY, sum = 0;
    for (int t = 0; t < grid->n_tets; t++)
        for (int e = 0; e < 6; e++) {
            const float *a = grid->verts + 3 * grid->tets[4 * t + pairs[e][0]],
                        *b = grid->verts + 3 * grid->tets[4 * t + pairs[e][1]];
            double len = sqrt(((double)a[0] - b[0]) * (a[0] - b[0]) + ((double)a[1] - b[1]) * (a[1] - b[1]) +
                              ((double)a[2] - b[2]) * (a[2] - b[2]));
            shortest = len < shortest ? len : shortest;
            sum += len;
        }
    return shortest > 1e-4 ? shortest : sum / (6.0 * grid->n_tets);
}
