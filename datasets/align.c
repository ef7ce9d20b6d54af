/* Yaw alignment (tcb/align.h): exhaustive over the 120 steps, frame after
 * frame. One symmetric Chamfer per candidate costs two nearest-neighbour
 * passes against fixed indices: CD(R·A, B) = mean_a d(R·a, B)² +
 * mean_b d(b, R·A)², and d(b, R·A) = d(Rᵀ·b, A), so frame t's index is
 * built once and queried with the rotated previous frame instead of being
 * rebuilt per angle. */
#include "tcb/align.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tcb/nn.h"

double tcb_align_step_radians(int step) { return 2.0 * M_PI * step / TCB_ALIGN_STEPS; }

/* out = R_y(θ)·p for n points (out may be p). */
static void rotate_y(float *out, const float *p, int n, double theta)
{
    double c = cos(theta), s = sin(theta);
    for (size_t i = 0; i < (size_t)n; i++) {
        double x = p[3 * i], y = p[3 * i + 1], z = p[3 * i + 2];
        out[3 * i] = (float)(c * x + s * z);
        out[3 * i + 1] = (float)y;
        out[3 * i + 2] = (float)(-s * x + c * z);
    }
}

static double mean_d2(const float *d2, int n)
{
    double s = 0;
    for (int i = 0; i < n; i++) s += d2[i];
    return s / n;
}

/* The same vertex ids in every frame rather than independent surface
 * samples per frame: two frames' Chamfer then carries no sampling noise of
 * its own (on crane, independent area samples of 1 000 points drifted up
 * to 8 steps from those of 10 000 along the sequence; docs/protocol.md D4). */
int tcb_align_vertex_ids(const tcb_sequence *s, int samples, uint64_t seed, int32_t *ids)
{
    int n = samples < s->n_verts ? samples : s->n_verts;
    for (int i = 0; i < s->n_verts; i++) ids[i] = i;
    char label[TCB_NAME_MAX + 16];
    snprintf(label, sizeof label, "align/%s", s->name);
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, seed, label);
    for (int i = 0; i < n && n < s->n_verts; i++) {
        int j = i + (int)tcb_rng_below(&rng, (uint32_t)(s->n_verts - i));
        int32_t t = ids[i];
        ids[i] = ids[j], ids[j] = t;
    }
    return n;
}

static void gather(const tcb_sequence *s, int f, const int32_t *ids, int n, float *out)
{
    const float *v = tcb_seq_frame(s, f);
    for (int i = 0; i < n; i++) memcpy(out + 3 * (size_t)i, v + 3 * (size_t)ids[i], 3 * sizeof(float));
}

typedef struct align_work {
    int n;
    float *cur, *prev;  /* [n][3] frame t (centred), frame t−1 (aligned) */
    float *rot, *d2;    /* [n][3], [n] scratch */
    int32_t *idx;       /* [n] */
} align_work;

/* The step minimising CD(R_k·cur, prev), and that distance. */
static int best_step(align_work *w, int *step, double *cd, tcb_error *err)
{
    tcb_nn *to_prev = NULL, *to_cur = NULL;
    int rc = tcb_nn_build(w->prev, w->n, &to_prev, err);
    if (!rc) rc = tcb_nn_build(w->cur, w->n, &to_cur, err);
    *step = 0, *cd = INFINITY;
    for (int k = 0; !rc && k < TCB_ALIGN_STEPS; k++) {
        double theta = tcb_align_step_radians(k);
        rotate_y(w->rot, w->cur, w->n, theta);
        rc = tcb_nn_query1(to_prev, w->rot, w->n, w->idx, w->d2, err);
        if (rc) break;
        double there = mean_d2(w->d2, w->n);
        rotate_y(w->rot, w->prev, w->n, -theta);
        rc = tcb_nn_query1(to_cur, w->rot, w->n, w->idx, w->d2, err);
        double both = rc ? INFINITY : there + mean_d2(w->d2, w->n);
        if (both < *cd) *cd = both, *step = k;
    }
    tcb_nn_free(to_prev);
    tcb_nn_free(to_cur);
    return rc;
}

int tcb_align_yaw(const tcb_sequence *s, int samples, uint64_t seed, int *step, double *chamfer,
                  tcb_error *err)
{
    if (samples < 1)
        return tcb_fail(err, TCB_ERR_INPUT, "sequence %s: alignment samples %d must be positive", s->name, samples);
    int32_t *ids = malloc((size_t)s->n_verts * sizeof *ids);
    int n = ids ? tcb_align_vertex_ids(s, samples, seed, ids) : 0;
    size_t n3 = (size_t)n * 3;
    align_work w = {n, malloc(n3 * sizeof(float)), malloc(n3 * sizeof(float)), malloc(n3 * sizeof(float)),
                    malloc((size_t)n * sizeof(float)), malloc((size_t)n * sizeof(int32_t))};
    int rc = ids && w.cur && w.prev && w.rot && w.d2 && w.idx
                 ? TCB_OK
                 : tcb_fail(err, TCB_ERR_NOMEM, "sequence %s: out of memory for the alignment", s->name);
    if (!rc) gather(s, 0, ids, n, w.prev);
    step[0] = 0;
    if (chamfer) chamfer[0] = 0;
    for (int f = 1; !rc && f < s->n_frames; f++) {
        double cd;
        gather(s, f, ids, n, w.cur);
        if ((rc = best_step(&w, &step[f], &cd, err))) {
            tcb_error_prefix(err, "sequence %s frame %d: alignment: ", s->name, f);
            break;
        }
        if (chamfer) chamfer[f] = cd;
        rotate_y(w.prev, w.cur, n, tcb_align_step_radians(step[f]));
    }
    free(ids), free(w.cur), free(w.prev), free(w.rot), free(w.d2), free(w.idx);
    return rc;
}

int tcb_sequence_apply_yaw(tcb_sequence *s, const int *step, tcb_error *err)
{
    if (s->pools)
        return tcb_fail(err, TCB_ERR_INTERNAL, "sequence %s: align before sampling pools", s->name);
    for (int f = 0; f < s->n_frames; f++)
        if (step[f] < 0 || step[f] >= TCB_ALIGN_STEPS)
            return tcb_fail(err, TCB_ERR_INPUT, "sequence %s frame %d: yaw step %d outside 0..%d", s->name, f,
                            step[f], TCB_ALIGN_STEPS - 1);
    if (!s->yaw && !(s->yaw = malloc((size_t)s->n_frames * sizeof *s->yaw)))
        return tcb_fail(err, TCB_ERR_NOMEM, "sequence %s: out of memory", s->name);
    for (int f = 0; f < s->n_frames; f++) {
        s->yaw[f] = tcb_align_step_radians(step[f]);
        float *v = s->verts + (size_t)f * s->n_verts * 3;
        rotate_y(v, v, s->n_verts, s->yaw[f]);
        if (s->track) {
            float *t = s->track + (size_t)f * s->n_track * 3;
            rotate_y(t, t, s->n_track, s->yaw[f]);
        }
    }
    return TCB_OK;
}
