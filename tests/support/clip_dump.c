/* Test helper (not installed): what a per-clip cell's clip metrics were
 * computed on, for an independent recomputation of DynoSurf's evaluation:
 *     clip_dump RUN_DIR DATASET/SEQUENCE METHOD OUT_DIR
 * reopens the cell's fitted model (views/cell_target.h) and writes, for
 * every frame f of the clip (the cell's sequence), little-endian:
 *     gt_verts.bin   float32 [F][nv][3]  the GT frames, as the cell's sequence has them
 *     faces.bin      int32   [nf][3]
 *     surf_verts.bin float32 [F][sv][3]  the method's surface of each frame (the
 *                                        Corr-mesh's vertices; one topology)
 *     surf_faces.bin int32   [sf][3]
 *     pred.bin, pred_n.bin, gt.bin, gt_n.bin  float32 [F][N][3]  the samples and normals
 *                                        the reconstruction metrics scored
 *                                        (tcb_cell_surface_samples), in their frame
 *     box.bin        float64 [F][4]      the frame's map into it (centre xyz, scale)
 *     meta.json      {"frames", "nv", "nf", "sv", "sf", "n", "recon_frame"}
 * (tests/integration/test_per_clip.sh). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "harness/harness_internal.h"
#include "tcb/json.h"
#include "views/cell_target.h"
#include "write_bin.h"

typedef struct dump {
    const char *out;
    const tcb_cell_job *job;
    const tcb_config *cfg;
    tcb_error herr;
} dump;

/* Appends bytes to OUT/name (a frame after the other). */
static int append(const char *dir, const char *name, const void *data, size_t bytes, tcb_error *err)
{
    return tcb_test_put_bin(dir, name, data, bytes, "ab", err);
}

static int write_meta(const dump *d, const tcb_uv_mesh *m, int n, tcb_error *err)
{
    const tcb_sequence *s = d->job->seq;
    char path[TCB_PATH_MAX];
    cJSON *o = cJSON_CreateObject();
    cJSON_AddNumberToObject(o, "frames", s->n_frames);
    cJSON_AddNumberToObject(o, "nv", s->n_verts);
    cJSON_AddNumberToObject(o, "nf", s->n_faces);
    cJSON_AddNumberToObject(o, "sv", m->n_verts);
    cJSON_AddNumberToObject(o, "sf", m->n_faces);
    cJSON_AddNumberToObject(o, "n", n);
    cJSON_AddStringToObject(o, "recon_frame", tcb_recon_frame_names[d->job->recon_frame]);
    int rc = tcb_path_join(path, sizeof path, err, "%s/meta.json", d->out);
    if (!rc) rc = tcb_json_save(path, o, err);
    cJSON_Delete(o);
    return rc;
}

/* Frame f: the method's surface, and the two sample sets with their map. */
static int dump_frame(dump *d, void *self, int f, tcb_surface_samples *s, tcb_error *merr)
{
    const tcb_sequence *seq = d->job->seq;
    tcb_rng rng;
    tcb_uv_mesh m;
    int rc = tcb_cell_method_surface(d->job, self, f, &rng, &m, merr);
    size_t bytes = (size_t)s->n * 3 * sizeof(float);
    double box[4] = {0, 0, 0, 0};
    if (!rc) rc = append(d->out, "surf_verts.bin", m.verts, (size_t)m.n_verts * 3 * sizeof(float), merr);
    if (!rc && f == 0) rc = tcb_test_write_bin(d->out, "surf_faces.bin", m.faces, (size_t)m.n_faces * 3 * 4, merr);
    if (!rc && f == 0) rc = write_meta(d, &m, s->n, merr);
    tcb_uv_mesh_free(&m);
    if (!rc) rc = tcb_cell_surface_samples(d->job, self, f, s, merr, &d->herr);
    if (!rc) rc = append(d->out, "pred.bin", s->pred, bytes, merr);
    if (!rc) rc = append(d->out, "pred_n.bin", s->pred_n, bytes, merr);
    if (!rc) rc = append(d->out, "gt.bin", s->gt, bytes, merr);
    if (!rc) rc = append(d->out, "gt_n.bin", s->gt_n, bytes, merr);
    memcpy(box, s->centre, sizeof s->centre), box[3] = s->scale;
    if (!rc) rc = append(d->out, "box.bin", box, sizeof box, merr);
    if (!rc) rc = append(d->out, "gt_verts.bin", tcb_seq_frame(seq, f), (size_t)seq->n_verts * 3 * sizeof(float), merr);
    return rc;
}

static int dump_clip(void *ctx, void *self, tcb_error *merr)
{
    dump *d = ctx;
    const tcb_sequence *seq = d->job->seq;
    tcb_surface_samples s = {0};
    int rc = tcb_surface_samples_init(&s, d->cfg->surface_samples, seq->n_verts, merr);
    for (int f = 0; !rc && f < seq->n_frames; f++) rc = dump_frame(d, self, f, &s, merr);
    if (!rc) rc = tcb_test_write_bin(d->out, "faces.bin", seq->faces, (size_t)seq->n_faces * 3 * 4, merr);
    tcb_surface_samples_free(&s);
    if (!rc && d->herr.code) rc = tcb_fail(merr, d->herr.code, "%s", d->herr.msg);
    return rc;
}

int main(int argc, char **argv)
{
    if (argc != 5) {
        fprintf(stderr, "usage: clip_dump RUN_DIR DATASET/SEQUENCE METHOD OUT_DIR\n");
        return 2;
    }
    tcb_config cfg = {0};
    tcb_cell_target t;
    tcb_cell_session sess;
    tcb_error err = {0};
    int rc = tcb_run_config_open(argv[1], &cfg, &err);
    if (!rc) rc = tcb_cell_target_resolve(&cfg, argv[3], -1, argv[2], &t, &err);
    if (!rc) rc = tcb_mkdirs(argv[4], &err);
    if (!rc) rc = tcb_cell_session_open(&cfg, argv[1], &t, 1, (tcb_reporter){0}, &sess, &err);
    if (!rc) {
        sess.job.recon_frame = cfg.recon_frame;
        dump d = {argv[4], &sess.job, &cfg, {0}};
        rc = tcb_cell_use_method(&sess.job, dump_clip, &d, &err);
        tcb_cell_session_close(&sess);
    }
    if (cfg.path[0]) tcb_config_free(&cfg);
    if (rc) fprintf(stderr, "clip_dump: %s\n", err.msg);
    return rc ? 1 : 0;
}
