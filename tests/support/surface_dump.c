/* Test helper (not installed): the reconstruction metrics of two frames of
 * a synthetic sequence as tcbench computes them, with the samples they were
 * computed on, for an independent recomputation:
 *     surface_dump N SEED A B OUT_DIR
 * Frame A of the embedded sequence quadruped_walk (8 frames) plays the
 * method's surface, frame B the ground truth; each is sampled with N points
 * (tcb_recon_sample) from the stream (SEED, "frame/<its index>"), so A = B
 * gives two identical sample sets. Writes to OUT_DIR, little-endian:
 *     verts.bin  float32 [F][nv][3]  the sequence's frames
 *     faces.bin  int32   [nf][3]
 *     pred.bin, pred_n.bin, gt.bin, gt_n.bin  float32 [N][3]  samples, normals
 *     pred_face.bin, gt_face.bin  int32 [N]  the face each sample lies on
 *         (tcb_sample_surface_faces from the same stream: the same draws)
 *     metrics.json  {"nv", "nf", "frames", "n", "cdl2", "nc", "fscore05", "fscore1"}
 * (tests/integration/test_surface_metrics.sh recomputes them with numpy and
 * scipy.spatial.cKDTree). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tcb/fsutil.h"
#include "tcb/geometry.h"
#include "tcb/json.h"
#include "tcb/metrics.h"
#include "tcb/rng.h"
#include "tcb/sequence.h"
#include "tcb/synth.h"
#include "write_bin.h"

#define FRAMES 8

/* Frame f's samples, normals and faces, written as <name>.bin, <name>_n.bin
 * and <name>_face.bin; pts and normals stay for the metrics. */
static int sample_frame(const tcb_sequence *s, int f, int n, uint64_t seed, const char *dir, const char *name,
                        float *pts, float *normals, tcb_error *err)
{
    char label[32], file[64];
    snprintf(label, sizeof label, "frame/%d", f);
    tcb_rng rng, again;
    tcb_rng_seed_stream(&rng, seed, label);
    again = rng;
    float *check = malloc((size_t)n * 3 * sizeof *check);
    int32_t *face = malloc((size_t)n * sizeof *face);
    int rc = check && face ? TCB_OK : tcb_fail(err, TCB_ERR_NOMEM, "out of memory");
    if (!rc) rc = tcb_recon_sample(tcb_seq_frame(s, f), s->faces, s->n_faces, n, &rng, pts, normals, err);
    if (!rc) rc = tcb_sample_surface_faces(tcb_seq_frame(s, f), s->faces, s->n_faces, n, &again, check, face, err);
    if (!rc && memcmp(check, pts, (size_t)n * 3 * sizeof *check))
        rc = tcb_fail(err, TCB_ERR_INTERNAL, "the same stream gave other points");
    size_t bytes = (size_t)n * 3 * sizeof(float);
    snprintf(file, sizeof file, "%s.bin", name);
    if (!rc) rc = tcb_test_write_bin(dir, file, pts, bytes, err);
    snprintf(file, sizeof file, "%s_n.bin", name);
    if (!rc) rc = tcb_test_write_bin(dir, file, normals, bytes, err);
    snprintf(file, sizeof file, "%s_face.bin", name);
    if (!rc) rc = tcb_test_write_bin(dir, file, face, (size_t)n * sizeof *face, err);
    free(check);
    free(face);
    return rc;
}

static int write_json(const char *dir, const tcb_sequence *s, int n, const double *v, tcb_error *err)
{
    char path[TCB_PATH_MAX];
    cJSON *o = cJSON_CreateObject();
    cJSON_AddNumberToObject(o, "nv", s->n_verts);
    cJSON_AddNumberToObject(o, "nf", s->n_faces);
    cJSON_AddNumberToObject(o, "frames", s->n_frames);
    cJSON_AddNumberToObject(o, "n", n);
    for (int m = 0; m < TCB_N_RECON; m++) cJSON_AddNumberToObject(o, tcb_recon_names[m], v[m]);
    int rc = tcb_path_join(path, sizeof path, err, "%s/metrics.json", dir);
    if (!rc) rc = tcb_json_save(path, o, err);
    cJSON_Delete(o);
    return rc;
}

int main(int argc, char **argv)
{
    int n = argc == 6 ? atoi(argv[1]) : 0, a = argc == 6 ? atoi(argv[3]) : -1, b = argc == 6 ? atoi(argv[4]) : -1;
    if (n < 1 || a < 0 || b < 0 || a >= FRAMES || b >= FRAMES) {
        fprintf(stderr, "usage: surface_dump N SEED A B OUT_DIR (N >= 1, frames A, B < %d)\n", FRAMES);
        return 2;
    }
    uint64_t seed = strtoull(argv[2], NULL, 10);
    const char *out = argv[5];
    tcb_sequence s = {0};
    tcb_error err = {0};
    size_t bytes = (size_t)n * 3 * sizeof(float);
    float *pred = malloc(bytes), *pred_n = malloc(bytes), *gt = malloc(bytes), *gt_n = malloc(bytes);
    double v[TCB_N_RECON];
    int rc = pred && pred_n && gt && gt_n ? TCB_OK : tcb_fail(&err, TCB_ERR_NOMEM, "out of memory");
    if (!rc) rc = tcb_synth_generate("quadruped_walk", 0, FRAMES, &s, &err);
    if (!rc) rc = tcb_mkdirs(out, &err);
    if (!rc) rc = sample_frame(&s, a, n, seed, out, "pred", pred, pred_n, &err);
    if (!rc) rc = sample_frame(&s, b, n, seed, out, "gt", gt, gt_n, &err);
    if (!rc) rc = tcb_recon_metrics(pred, pred_n, n, gt, gt_n, n, v, &err);
    if (!rc) rc = tcb_test_write_bin(out, "verts.bin", s.verts, (size_t)s.n_frames * s.n_verts * 3 * sizeof(float), &err);
    if (!rc) rc = tcb_test_write_bin(out, "faces.bin", s.faces, (size_t)s.n_faces * 3 * sizeof(int32_t), &err);
    if (!rc) rc = write_json(out, &s, n, v, &err);
    free(pred), free(pred_n), free(gt), free(gt_n);
    tcb_sequence_free(&s);
    if (rc) fprintf(stderr, "surface_dump: %s\n", err.msg);
    return rc ? 1 : 0;
}
