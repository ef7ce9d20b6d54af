/* The pcgrid methods' template (methods/pcgrid/template.h): the keyframe's
 * normals, its Poisson surface, PDG's remeshing rounds and the decimation,
 * the template's vertex normals and edges, and its OBJ. */
#include "methods/pcgrid/template.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "tcb/fsutil.h"
#include "tcb/geodesic.h"
#include "tcb/geometry.h"
#include "tcb/locate.h"
#include "tcb/mesh_io.h"
#include "tcb/meshing.h"
#include "tcb/metrics.h"
#include "tcb/rng.h"

/* The unit normal of triangle (a, b, c), in double as the reference's
 * face normals; zero for a degenerate one. */
static void unit_face_normal(const float *a, const float *b, const float *c, float *out)
{
    double u[3], v[3], nn[3], len;
    for (int k = 0; k < 3; k++) u[k] = (double)b[k] - a[k], v[k] = (double)c[k] - a[k];
    nn[0] = u[1] * v[2] - u[2] * v[1], nn[1] = u[2] * v[0] - u[0] * v[2], nn[2] = u[0] * v[1] - u[1] * v[0];
    len = sqrt(nn[0] * nn[0] + nn[1] * nn[1] + nn[2] * nn[2]);
    for (int k = 0; k < 3; k++) out[k] = (float)(len > 0 ? nn[k] / len : 0.0);
}

int tcb_pcgrid_gt_normals(const tcb_sequence *seq, int key, const tcb_pcgrid_frame_map *map, const float *cloud,
                          int n, float *normals, tcb_error *err)
{
    if (!seq->n_faces)
        return tcb_fail(err, TCB_ERR_INPUT, "GT normals need the GT surface, and sequence %s is points alone "
                        "(\"normals\": \"estimated\", or \"input_normals\": \"estimated\")", seq->name);
    float *gt = malloc((size_t)seq->n_verts * 3 * sizeof *gt);
    tcb_surface_point *loc = malloc((size_t)n * sizeof *loc);
    int rc = gt && loc ? TCB_OK : tcb_fail(err, TCB_ERR_NOMEM, "template: out of memory");
    if (!rc) {
        tcb_pcgrid_map_points(map, tcb_seq_frame(seq, key), seq->n_verts, gt);
        rc = tcb_mesh_locate(gt, seq->n_verts, seq->faces, seq->n_faces, cloud, n, loc, NULL, err);
    }
    for (int i = 0; !rc && i < n; i++) {
        const int32_t *f = seq->faces + 3 * (size_t)loc[i].face;
        unit_face_normal(gt + 3 * (size_t)f[0], gt + 3 * (size_t)f[1], gt + 3 * (size_t)f[2],
                         normals + 3 * (size_t)i);
    }
    free(gt), free(loc);
    return rc;
}

/* The mean length of the mesh's half-edges (remesh_botsch's default
 * target). */
static double mean_edge_length(const tcb_mesh *m)
{
    double sum = 0.0;
    for (int f = 0; f < m->n_faces; f++)
        for (int k = 0; k < 3; k++) {
            const float *p = m->verts + 3 * (size_t)m->faces[3 * f + k],
                        *q = m->verts + 3 * (size_t)m->faces[3 * f + (k + 1) % 3];
            double d = 0.0;
            for (int j = 0; j < 3; j++) d += ((double)p[j] - q[j]) * ((double)p[j] - q[j]);
            sum += sqrt(d);
        }
    return sum / (3.0 * m->n_faces);
}

/* The Chamfer between samples of two meshes. */
static int sampled_chamfer(const tcb_mesh *a, const tcb_mesh *b, int n, tcb_rng *rng, double *cd, tcb_error *err)
{
    float *pa = malloc((size_t)n * 3 * sizeof *pa), *pb = malloc((size_t)n * 3 * sizeof *pb);
    int rc = pa && pb ? TCB_OK : tcb_fail(err, TCB_ERR_NOMEM, "template: out of memory");
    if (!rc) rc = tcb_sample_surface(a->verts, a->faces, a->n_faces, n, rng, pa, err);
    if (!rc) rc = tcb_sample_surface(b->verts, b->faces, b->n_faces, n, rng, pb, err);
    if (!rc) rc = tcb_chamfer(pa, n, pb, n, cd, err);
    free(pa), free(pb);
    return rc;
}

/* PDG's rounds: remesh, decimate, check; the next round remeshes the
 * remeshed surface. */
static int remesh_rounds(const tcb_mesh *surface, const tcb_pcgrid_template_spec *spec, tcb_mesh *out,
                         tcb_error *err)
{
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, spec->seed, "pcgrid/template-check");
    tcb_mesh current = *surface, remeshed = {0, 0, NULL, NULL};
    double cd = NAN;
    int rc = TCB_OK;
    for (int round = 0; !rc && round < spec->max_rounds; round++) {
        rc = tcb_mesh_remesh(&current, mean_edge_length(&current), spec->remesh_iterations, &remeshed, err);
        if (current.verts != surface->verts) tcb_mesh_free(&current);
        if (!rc) rc = tcb_mesh_decimate(&remeshed, spec->template_faces, out, err);
        if (!rc) rc = sampled_chamfer(out, &remeshed, spec->check_samples, &rng, &cd, err);
        if (!rc && cd < spec->check_chamfer) {
            tcb_mesh_free(&remeshed);
            return TCB_OK;
        }
        if (!rc) tcb_mesh_free(out);
        current = remeshed;
        memset(&remeshed, 0, sizeof remeshed);
    }
    if (current.verts != surface->verts) tcb_mesh_free(&current);
    if (rc) return rc;
    return tcb_fail(err, TCB_ERR_NUMERIC,
                    "template: the decimation stayed %.3g from the remeshed surface (Chamfer; at most %.3g) after %d "
                    "rounds",
                    cd, spec->check_chamfer, spec->max_rounds);
}

int tcb_pcgrid_template_build(const tcb_sequence *seq, int key, const tcb_pcgrid_frame_map *map,
                              const float *cloud, int n, const tcb_pcgrid_template_spec *spec, tcb_mesh *out,
                              tcb_error *err)
{
    float *normals = malloc((size_t)n * 3 * sizeof *normals);
    tcb_mesh surface = {0, 0, NULL, NULL};
    int rc = !normals              ? tcb_fail(err, TCB_ERR_NOMEM, "template: out of memory")
             : spec->gt_normals ? tcb_pcgrid_gt_normals(seq, key, map, cloud, n, normals, err)
                                : tcb_estimate_normals(cloud, n, TCB_NORMALS_K, normals, err);
    if (!rc) rc = tcb_poisson_reconstruct(cloud, normals, n, spec->poisson_depth, &surface, err);
    if (!rc)
        rc = spec->remesh_iterations ? remesh_rounds(&surface, spec, out, err)
                                     : tcb_mesh_decimate(&surface, spec->template_faces, out, err);
    tcb_mesh_free(&surface);
    free(normals);
    return rc;
}

int tcb_pcgrid_template_normals(const tcb_mesh *t, float **normals, tcb_error *err)
{
    if (!(*normals = malloc((size_t)t->n_verts * 3 * sizeof **normals)))
        return tcb_fail(err, TCB_ERR_NOMEM, "template: out of memory");
    tcb_vertex_normals(t->verts, t->n_verts, t->faces, t->n_faces, *normals);
    return TCB_OK;
}

/* The length of the edge between vertices a and b of t, in double. */
static float edge_length(const tcb_mesh *t, int a, int b)
{
    const float *p = t->verts + 3 * (size_t)a, *q = t->verts + 3 * (size_t)b;
    double d = 0.0;
    for (int k = 0; k < 3; k++) d += ((double)p[k] - q[k]) * ((double)p[k] - q[k]);
    return (float)sqrt(d);
}

int tcb_pcgrid_template_edges(const tcb_mesh *t, int32_t **edges, float **edge_len, int *ne, tcb_error *err)
{
    *edges = NULL, *edge_len = NULL, *ne = 0;
    tcb_edge_graph g;
    int rc = tcb_edge_graph_build(t->faces, t->n_faces, t->n_verts, &g, err);
    if (rc) return rc;
    int32_t *e2 = malloc(2 * (size_t)g.n_edges * sizeof *e2);
    float *len = malloc((size_t)g.n_edges * sizeof *len);
    int n = 0;
    if (!e2 || !len) rc = tcb_fail(err, TCB_ERR_NOMEM, "template: out of memory");
    for (int a = 0; !rc && a < g.n_verts; a++)
        for (int e = g.offsets[a]; e < g.offsets[a + 1]; e++) {
            int b = g.adj[e];
            if (b < a) continue; /* each undirected edge once, from its lower vertex */
            e2[2 * n] = a, e2[2 * n + 1] = b;
            len[n++] = edge_length(t, a, b);
        }
    tcb_edge_graph_free(&g);
    if (rc) {
        free(e2), free(len);
        return rc;
    }
    *edges = e2, *edge_len = len, *ne = n;
    return TCB_OK;
}

int tcb_pcgrid_template_write(const tcb_mesh *t, const tcb_pcgrid_frame_map *map, const char *work_dir,
                              int keyframe, tcb_error *err)
{
    char path[TCB_PATH_MAX];
    float *verts = malloc((size_t)t->n_verts * 3 * sizeof *verts);
    if (!verts) return tcb_fail(err, TCB_ERR_NOMEM, "template: out of memory");
    memcpy(verts, t->verts, (size_t)t->n_verts * 3 * sizeof *verts);
    tcb_pcgrid_unmap_points(map, verts, t->n_verts);
    int rc = tcb_path_join(path, sizeof path, err, "%s/template_keyframe_%d.obj", work_dir, keyframe);
    if (!rc) rc = tcb_obj_write(path, verts, t->n_verts, t->faces, t->n_faces, err);
    free(verts);
    return rc;
}
