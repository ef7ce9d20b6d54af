/* Test helper (not installed): one pair's geodesic error as tcbench
 * computes it, with everything an independent reference needs to redo it:
 *     geodesic_dump OBJ_DIR I J nearest|random SEED OUT_DIR
 * The OBJ frames are read and normalised as the ANIM datasets are
 * (first_frame); the prediction of frame i's vertices on frame j is the
 * nearest vertex (the `nearest` baseline) or uniform random (seeded). Writes
 * to OUT_DIR, little-endian:
 *     verts.bin  float32 [nv][3]  frame j, normalised
 *     faces.bin  int32   [nf][3]  the triangles (polygons fan-split by the reader)
 *     pred.bin   int32   [nv]     the predicted vertex of frame j per vertex
 *     geo.bin    float64 [nv]     each vertex's normalised geodesic error
 *     pair.json  {"nv", "nf", "area", "m_geo", "geo_auc", "geo_pck": [...], "unreachable"}
 * (tests/integration/test_geodesic_scipy.sh compares them with scipy). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tcb/fsutil.h"
#include "tcb/geodesic.h"
#include "tcb/json.h"
#include "tcb/rng.h"
#include "tcb/sequence.h"
#include "write_bin.h"

static int die(const tcb_error *err)
{
    fprintf(stderr, "geodesic_dump: %s\n", err->msg);
    return 1;
}

static int write_json(const char *dir, const tcb_sequence *s, int j, const tcb_pair_metrics *m,
                      tcb_error *err)
{
    char path[TCB_PATH_MAX];
    cJSON *o = cJSON_CreateObject();
    cJSON_AddNumberToObject(o, "nv", s->n_verts);
    cJSON_AddNumberToObject(o, "nf", s->n_faces);
    cJSON_AddNumberToObject(o, "area", s->areas[j]);
    cJSON_AddNumberToObject(o, "m_geo", m->geo.mean);
    cJSON_AddNumberToObject(o, "geo_auc", m->geo_auc);
    cJSON_AddItemToObject(o, "geo_pck", cJSON_CreateDoubleArray(m->geo_pck, TCB_GEO_PCK_STEPS));
    cJSON_AddNumberToObject(o, "unreachable", m->geo_unreachable);
    int rc = tcb_path_join(path, sizeof path, err, "%s/pair.json", dir);
    if (!rc) rc = tcb_json_save(path, o, err);
    cJSON_Delete(o);
    return rc;
}

static void predict(const tcb_sequence *s, int i, int j, const char *mode, uint64_t seed, int32_t *pred,
                    tcb_error *err)
{
    if (!strcmp(mode, "nearest")) {
        tcb_project_to_vertices(tcb_seq_frame(s, j), s->n_verts, tcb_seq_frame(s, i), s->n_verts, pred, err);
        return;
    }
    tcb_rng rng;
    tcb_rng_seed(&rng, seed);
    for (int k = 0; k < s->n_verts; k++) pred[k] = (int32_t)tcb_rng_below(&rng, (uint64_t)s->n_verts);
}

int main(int argc, char **argv)
{
    if (argc != 7 || (strcmp(argv[4], "nearest") && strcmp(argv[4], "random"))) {
        fprintf(stderr, "usage: geodesic_dump OBJ_DIR I J nearest|random SEED OUT_DIR\n");
        return 2;
    }
    tcb_sequence s = {0};
    tcb_error err = {0};
    int i = atoi(argv[2]), j = atoi(argv[3]);
    const char *out = argv[6];
    if (tcb_sequence_read_objdir(argv[1], &s, &err) ||
        tcb_sequence_normalize(&s, TCB_NORM_FIRST_FRAME, &err))
        return die(&err);
    if (i < 0 || j < 0 || i >= s.n_frames || j >= s.n_frames) {
        fprintf(stderr, "geodesic_dump: frames %d, %d: the sequence has %d\n", i, j, s.n_frames);
        return 2;
    }
    size_t nv = (size_t)s.n_verts;
    int32_t *pred = malloc(nv * sizeof *pred);
    double *geo = malloc(nv * sizeof *geo);
    tcb_edge_graph g = {0};
    tcb_pair_metrics m = {0};
    int rc = !pred || !geo ? tcb_fail(&err, TCB_ERR_NOMEM, "out of memory") : TCB_OK;
    if (!rc) predict(&s, i, j, argv[4], strtoull(argv[5], NULL, 10), pred, &err), rc = err.code;
    if (!rc) rc = tcb_edge_graph_build(s.faces, s.n_faces, s.n_verts, &g, &err);
    if (!rc) rc = tcb_pair_geodesic_compute(&g, tcb_seq_frame(&s, j), s.areas[j], pred, &m, geo, &err);
    if (!rc) rc = tcb_mkdirs(out, &err);
    if (!rc) rc = tcb_test_write_bin(out, "verts.bin", tcb_seq_frame(&s, j), nv * 3 * sizeof(float), &err);
    if (!rc) rc = tcb_test_write_bin(out, "faces.bin", s.faces, (size_t)s.n_faces * 3 * sizeof(int32_t), &err);
    if (!rc) rc = tcb_test_write_bin(out, "pred.bin", pred, nv * sizeof *pred, &err);
    if (!rc) rc = tcb_test_write_bin(out, "geo.bin", geo, nv * sizeof *geo, &err);
    if (!rc) rc = write_json(out, &s, j, &m, &err);
    tcb_edge_graph_free(&g);
    free(pred);
    free(geo);
    tcb_sequence_free(&s);
    return rc ? die(&err) : 0;
}
