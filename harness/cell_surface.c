/* The reconstruction metrics of a cell (tcb/metrics.h, TCB_RECON_*): for
 * every frame the evaluation uses, once, the method's surface of the frame
 * (tcb_method_ops.surface) against the frame's GT mesh, each sampled with
 * job->surface_samples area-uniform points. The method's surface and its
 * samples draw from the stream "surface/<dataset>/<sequence>/<frame>" of the
 * cell's seed, the GT samples from "surface_gt/…": the same GT samples for
 * every method of a seed, so methods are compared on the same points. */
#include <limits.h>
#include <stdlib.h>
#include <string.h>

#include "harness/harness_internal.h"
#include "scoring/scoring.h"

void tcb_surface_samples_free(tcb_surface_samples *s)
{
    free(s->pred), free(s->pred_n), free(s->gt), free(s->gt_n), free(s->gt_verts);
    memset(s, 0, sizeof *s);
}

int tcb_surface_samples_init(tcb_surface_samples *s, int n, int n_verts, tcb_error *herr)
{
    size_t bytes = (size_t)n * 3 * sizeof(float);
    *s = (tcb_surface_samples){n, malloc(bytes), malloc(bytes), malloc(bytes), malloc(bytes),
                               malloc((size_t)n_verts * 3 * sizeof(float)), {0, 0, 0}, 1.0};
    if (s->pred && s->pred_n && s->gt && s->gt_n && s->gt_verts) return TCB_OK;
    tcb_surface_samples_free(s);
    return tcb_fail(herr, TCB_ERR_NOMEM, "out of memory for %d surface samples", n);
}

static void frame_stream(const tcb_cell_job *job, const char *what, int frame, tcb_rng *rng)
{
    char label[TCB_PATH_MAX];
    snprintf(label, sizeof label, "%s/%s/%s/%d", what, job->dataset->name, job->seq->name, frame);
    tcb_rng_seed_stream(rng, (uint64_t)job->seed, label);
}

int tcb_cell_method_surface(const tcb_cell_job *job, void *self, int frame, tcb_rng *rng, tcb_uv_mesh *m,
                            tcb_error *merr)
{
    frame_stream(job, "surface", frame, rng);
    *m = (tcb_uv_mesh){0, 0, 0, NULL, NULL, NULL, NULL};
    int rc = job->ops->surface(self, job->seq, frame, rng, m, merr);
    if (rc) {
        tcb_cell_ensure_error(merr, rc);
        tcb_error_prefix(merr, "surface of frame %d: ", frame);
    }
    if (!rc) rc = tcb_surface_check(m, frame, INT_MAX, merr);
    if (rc) tcb_uv_mesh_free(m);
    return rc;
}

/* The method's surface of `frame`, sampled into s->pred / s->pred_n; its
 * failures (a bad mesh, one of no area) are the method's. */
static int method_samples(const tcb_cell_job *job, void *self, int frame, tcb_surface_samples *s, tcb_error *merr)
{
    tcb_rng rng;
    tcb_uv_mesh m;
    int rc = tcb_cell_method_surface(job, self, frame, &rng, &m, merr);
    if (!rc && job->recon_frame == TCB_RECON_FRAME_BOX) tcb_frame_box_apply(s->centre, s->scale, m.verts, m.n_verts);
    if (!rc && (rc = tcb_recon_sample(m.verts, m.faces, m.n_faces, s->n, &rng, s->pred, s->pred_n, merr)))
        tcb_error_prefix(merr, "surface of frame %d: ", frame);
    tcb_uv_mesh_free(&m);
    return rc;
}

/* The frame's GT vertices in the metrics' frame into s->gt_verts, and
 * under TCB_RECON_FRAME_BOX the map the method's surface gets too. */
static void gt_frame(const tcb_cell_job *job, int frame, tcb_surface_samples *s)
{
    const tcb_sequence *seq = job->seq;
    memcpy(s->gt_verts, tcb_seq_frame(seq, frame), (size_t)seq->n_verts * 3 * sizeof(float));
    if (job->recon_frame != TCB_RECON_FRAME_BOX) return;
    tcb_frame_box_map(s->gt_verts, seq->n_verts, s->centre, &s->scale);
    tcb_frame_box_apply(s->centre, s->scale, s->gt_verts, seq->n_verts);
}

int tcb_cell_surface_samples(const tcb_cell_job *job, void *self, int frame, tcb_surface_samples *s,
                             tcb_error *merr, tcb_error *herr)
{
    const tcb_sequence *seq = job->seq;
    gt_frame(job, frame, s);
    if (method_samples(job, self, frame, s, merr)) return merr->code;
    tcb_rng rng;
    frame_stream(job, "surface_gt", frame, &rng);
    return tcb_recon_sample(s->gt_verts, seq->faces, seq->n_faces, s->n, &rng, s->gt, s->gt_n, herr);
}

static int frame_metrics(const tcb_cell_job *job, void *self, int frame, tcb_surface_samples *s,
                         tcb_surface_record *rec, tcb_error *merr, tcb_error *herr)
{
    rec->frame = frame;
    int rc = tcb_cell_surface_samples(job, self, frame, s, merr, herr);
    if (!rc) rc = tcb_recon_metrics(s->pred, s->pred_n, s->n, s->gt, s->gt_n, s->n, rec->v, herr);
    if (rc && herr->code) tcb_error_prefix(herr, "surface metrics of frame %d: ", frame);
    return rc;
}

/* The frames of the split's pairs and of the clips into used[n_frames];
 * returns how many. */
static int mark_frames(const tcb_cell_job *job, unsigned char *used)
{
    for (int k = 0; k < 2 * job->split->n_pairs; k++) used[job->split->pairs[k]] = 1;
    for (int c = 0; job->clips && c < job->clips->n_clips; c++)
        for (int t = 0; t < TCB_CLIP_FRAMES; t++) used[job->clips->starts[c] + t] = 1;
    int n = 0;
    for (int f = 0; f < job->seq->n_frames; f++) n += used[f];
    return n;
}

/* A stop request ends the reconstruction metrics between two frames (a
 * frame of 100 000 samples takes a second or more). */
static int stopped(const tcb_cell_job *job, int done, int total, tcb_error *herr)
{
    if (!job->interrupted || !job->interrupted(job->interrupt_arg)) return 0;
    tcb_fail(herr, TCB_ERR_INTERRUPTED,
             "stopped at frame %d of %d of the reconstruction metrics (the fitted model is kept)", done, total);
    return 1;
}

void tcb_cell_surface_metrics(const tcb_cell_job *job, void *self, tcb_cell_result *c, tcb_error *merr,
                              tcb_error *herr)
{
    /* points alone (no GT surface): nothing to measure a surface against */
    if (job->surface_samples <= 0 || !tcb_method_has_surface(job->ops) || !job->seq->n_faces) return;
    unsigned char *used = calloc((size_t)job->seq->n_frames, 1);
    tcb_surface_samples s = {0};
    if (!used || tcb_surface_samples_init(&s, job->surface_samples, job->seq->n_verts, herr)) {
        free(used);
        if (!herr->code) tcb_fail(herr, TCB_ERR_NOMEM, "out of memory for %d frames", job->seq->n_frames);
        return;
    }
    int n = mark_frames(job, used);
    c->surface = calloc((size_t)n + 1, sizeof *c->surface);
    if (!c->surface) tcb_fail(herr, TCB_ERR_NOMEM, "out of memory for %d frames", n);
    for (int f = 0, k = 0; c->surface && f < job->seq->n_frames && !merr->code && !herr->code; f++) {
        if (!used[f] || stopped(job, k, n, herr) || frame_metrics(job, self, f, &s, &c->surface[k], merr, herr))
            continue;
        for (int m = 0; m < TCB_N_RECON; m++) tcb_stat_push(&c->summary.recon[m], c->surface[k].v[m]);
        c->n_surface = ++k;
    }
    c->surface_samples = job->surface_samples;
    c->surface_frame = job->recon_frame;
    free(used);
    tcb_surface_samples_free(&s);
}
