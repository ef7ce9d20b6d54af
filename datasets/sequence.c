/* tcb_sequence: allocation, normalization (reference-protocol §1.3), point
 * pools and per-fetch input draws (§1.2). */
#include "tcb/sequence.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tcb/align.h"
#include "tcb/geometry.h"

int tcb_sequence_alloc(tcb_sequence *s, const char *name, int n_frames, int n_verts,
                       int n_faces, tcb_error *err)
{
    memset(s, 0, sizeof *s);
    s->norm_scale = 1.0;
    s->input_points = TCB_DEFAULT_INPUT_POINTS;
    if (n_frames <= 0 || n_verts <= 0 || n_faces < 0)
        return tcb_fail(err, TCB_ERR_INPUT, "sequence %s: bad sizes (%d frames, %d vertices, %d faces)",
                        name, n_frames, n_verts, n_faces);
    size_t len = strlen(name);
    if (len >= TCB_NAME_MAX)
        return tcb_fail(err, TCB_ERR_INPUT, "sequence name '%.40s...' longer than %d characters", name,
                        TCB_NAME_MAX - 1);
    memcpy(s->name, name, len + 1);
    s->n_frames = n_frames;
    s->n_verts = n_verts;
    s->n_faces = n_faces;
    s->verts = malloc((size_t)n_frames * (size_t)n_verts * 3 * sizeof(float));
    s->faces = n_faces ? malloc((size_t)n_faces * 3 * sizeof(int32_t)) : NULL;
    if (!s->verts || (n_faces && !s->faces)) {
        tcb_sequence_free(s);
        return tcb_fail(err, TCB_ERR_NOMEM, "sequence %s: cannot allocate %d frames of %d vertices",
                        name, n_frames, n_verts);
    }
    return TCB_OK;
}

void tcb_sequence_free(tcb_sequence *s)
{
    free(s->verts);
    free(s->faces);
    free(s->areas);
    free(s->pools);
    free(s->norm_shift);
    free(s->yaw);
    free(s->blocks);
    free(s->track);
    memset(s, 0, sizeof *s);
}

/* FIRST_FRAME: c = frame 0's vertex mean, scale = its largest bbox extent. */
static int first_frame_transform(const tcb_sequence *s, double c[3], double *scale, tcb_error *err)
{
    const float *v = tcb_seq_frame(s, 0);
    double lo[3], hi[3];
    for (int d = 0; d < 3; d++) {
        c[d] = 0.0;
        lo[d] = hi[d] = v[d];
    }
    for (int i = 0; i < s->n_verts; i++)
        for (int d = 0; d < 3; d++) {
            double x = v[3 * (size_t)i + d];
            c[d] += x;
            lo[d] = fmin(lo[d], x);
            hi[d] = fmax(hi[d], x);
        }
    *scale = 0.0;
    for (int d = 0; d < 3; d++) {
        c[d] /= s->n_verts;
        *scale = fmax(*scale, hi[d] - lo[d]);
    }
    if (!(*scale > 0.0) || !isfinite(*scale))
        return tcb_fail(err, TCB_ERR_INPUT, "sequence %s: first frame has extent %g, cannot normalize",
                        s->name, *scale);
    return TCB_OK;
}

/* CLIP_BBOX: c = the centre of the box of every frame's vertices, scale =
 * half its largest extent / 0.95 (Neu-PiG's and PDG's frame: the
 * sequence fills 95 % of [-1, 1]³). */
static int clip_bbox_transform(const tcb_sequence *s, double c[3], double *scale, tcb_error *err)
{
    double box[6];
    tcb_bbox(s->verts, (size_t)s->n_frames * (size_t)s->n_verts, box);
    *scale = 0.0;
    for (int d = 0; d < 3; d++) {
        c[d] = 0.5 * (box[d] + box[3 + d]);
        *scale = fmax(*scale, 0.5 * (box[3 + d] - box[d]));
    }
    *scale /= TCB_CLIP_BBOX_MARGIN;
    if (!(*scale > 0.0) || !isfinite(*scale))
        return tcb_fail(err, TCB_ERR_INPUT, "sequence %s: its frames' box has half extent %g, cannot normalize",
                        s->name, *scale * TCB_CLIP_BBOX_MARGIN);
    return TCB_OK;
}

/* FIRST_FRAME_DIAG: c = frame 0's vertex mean, scale = the diagonal of
 * frame 0's bounding box (DynoSurf's frame). */
static int first_frame_diag_transform(const tcb_sequence *s, double c[3], double *scale, tcb_error *err)
{
    double unused;
    int rc = first_frame_transform(s, c, &unused, err);
    if (rc) return rc;
    double box[6];
    tcb_bbox(tcb_seq_frame(s, 0), (size_t)s->n_verts, box);
    *scale = tcb_bbox_diag(box);
    if (!(*scale > 0.0) || !isfinite(*scale))
        return tcb_fail(err, TCB_ERR_INPUT, "sequence %s: first frame has diagonal %g, cannot normalize",
                        s->name, *scale);
    return TCB_OK;
}

/* The similarity every frame gets (none and per_frame: identity here;
 * per_frame centres each frame below). */
static int norm_transform(const tcb_sequence *s, tcb_normalization mode, double c[3], double *scale, tcb_error *err)
{
    c[0] = c[1] = c[2] = 0.0, *scale = 1.0;
    switch (mode) {
    case TCB_NORM_NONE:
    case TCB_NORM_PER_FRAME: return TCB_OK;
    case TCB_NORM_FIRST_FRAME: return first_frame_transform(s, c, scale, err);
    case TCB_NORM_CLIP_BBOX: return clip_bbox_transform(s, c, scale, err);
    case TCB_NORM_FIRST_FRAME_DIAG: return first_frame_diag_transform(s, c, scale, err);
    }
    return tcb_fail(err, TCB_ERR_INPUT, "sequence %s: unknown normalization %d", s->name, (int)mode);
}

/* The mean of n points: per_frame's centre of a sequence of points alone. */
static void points_centroid(const float *v, int n, double c[3])
{
    c[0] = c[1] = c[2] = 0.0;
    for (int i = 0; i < n; i++)
        for (int d = 0; d < 3; d++) c[d] += v[3 * (size_t)i + d];
    for (int d = 0; d < 3; d++) c[d] /= n;
}

int tcb_sequence_normalize(tcb_sequence *s, tcb_normalization mode, tcb_error *err)
{
    if (s->pools)
        return tcb_fail(err, TCB_ERR_INTERNAL, "sequence %s: normalize before sampling pools", s->name);
    double c[3], scale;
    int rc = norm_transform(s, mode, c, &scale, err);
    if (rc) return rc;
    if (!s->areas) s->areas = malloc((size_t)s->n_frames * sizeof *s->areas);
    if (!s->norm_shift) s->norm_shift = malloc((size_t)s->n_frames * 3 * sizeof *s->norm_shift);
    if (!s->areas || !s->norm_shift)
        return tcb_fail(err, TCB_ERR_NOMEM, "sequence %s: out of memory", s->name);
    for (int f = 0; f < s->n_frames; f++) {
        float *v = s->verts + (size_t)f * s->n_verts * 3;
        double *shift = s->norm_shift + 3 * (size_t)f;
        /* PER_FRAME stands in for the authors' per-fetch centroid of the
         * 2500 drawn points: its expectation, so deterministic. */
        if (mode == TCB_NORM_PER_FRAME && s->n_faces) tcb_surface_centroid(v, s->faces, s->n_faces, c);
        if (mode == TCB_NORM_PER_FRAME && !s->n_faces) points_centroid(v, s->n_verts, c);
        memcpy(shift, c, sizeof c);
        for (size_t i = 0; i < 3 * (size_t)s->n_verts; i++)
            v[i] = (float)(((double)v[i] - shift[i % 3]) / scale);
        float *t = s->track ? s->track + (size_t)f * s->n_track * 3 : NULL;
        for (size_t i = 0; t && i < 3 * (size_t)s->n_track; i++)
            t[i] = (float)(((double)t[i] - shift[i % 3]) / scale);
        s->areas[f] = tcb_mesh_area(v, s->faces, s->n_faces);
    }
    s->norm = mode;
    s->norm_scale = scale;
    return TCB_OK;
}

int tcb_sequence_cut(const tcb_sequence *from, int start, int n_frames, const char *name, tcb_sequence *out,
                     tcb_error *err)
{
    memset(out, 0, sizeof *out);
    int lo, hi;
    if (start < 0 || n_frames < 1 || start + n_frames > from->n_frames)
        return tcb_fail(err, TCB_ERR_INPUT, "sequence %s has %d frames: no frames %d-%d to cut %s from", from->name,
                        from->n_frames, start, start + n_frames - 1, name);
    int block = tcb_seq_block_of(from, start, &lo, &hi);
    if (start + n_frames > hi)
        return tcb_fail(err, TCB_ERR_INPUT, "sequence %s: frames %d-%d of %s cross the end of block %s (frames %d-%d)",
                        from->name, start, start + n_frames - 1, name,
                        block >= 0 && from->n_blocks ? from->blocks[block].name : "?", lo, hi - 1);
    int rc = tcb_sequence_alloc(out, name, n_frames, from->n_verts, from->n_faces, err);
    if (rc) return rc;
    size_t frame = (size_t)from->n_verts * 3;
    memcpy(out->verts, from->verts + (size_t)start * frame, (size_t)n_frames * frame * sizeof *out->verts);
    if (from->n_faces) memcpy(out->faces, from->faces, (size_t)from->n_faces * 3 * sizeof *out->faces);
    out->input_points = from->input_points;
    out->draw_with_replacement = from->draw_with_replacement;
    out->input_normals = from->input_normals;
    if (!from->track) return TCB_OK;
    size_t track = (size_t)from->n_track * 3;
    if (!(out->track = malloc((size_t)n_frames * track * sizeof *out->track))) {
        tcb_sequence_free(out);
        return tcb_fail(err, TCB_ERR_NOMEM, "sequence %s: out of memory", name);
    }
    memcpy(out->track, from->track + (size_t)start * track, (size_t)n_frames * track * sizeof *out->track);
    out->n_track = from->n_track;
    return TCB_OK;
}

/* Without faces the vertices are the surface's samples (Occupancy Flow
 * drew them by area): a pool is n of them, uniformly with replacement. */
static int sample_points(const tcb_sequence *s, int f, int n, tcb_rng *rng, float *out)
{
    const float *v = tcb_seq_frame(s, f);
    for (int i = 0; i < n; i++)
        memcpy(out + 3 * (size_t)i, v + 3 * (size_t)tcb_rng_below(rng, (uint32_t)s->n_verts), 3 * sizeof(float));
    return TCB_OK;
}

int tcb_sequence_sample_pools(tcb_sequence *s, int pool_size, uint64_t seed, tcb_error *err)
{
    if (pool_size <= 0)
        return tcb_fail(err, TCB_ERR_INPUT, "sequence %s: pool size %d must be positive", s->name, pool_size);
    float *pools = malloc((size_t)s->n_frames * (size_t)pool_size * 3 * sizeof(float));
    if (!pools)
        return tcb_fail(err, TCB_ERR_NOMEM, "sequence %s: cannot allocate pools of %d points", s->name,
                        pool_size);
    for (int f = 0; f < s->n_frames; f++) {
        /* One stream per frame: a frame's pool does not depend on how many
         * frames precede it or on the order they are sampled in. */
        char label[TCB_NAME_MAX + 32];
        snprintf(label, sizeof label, "pool/%s/%d", s->name, f);
        tcb_rng rng;
        tcb_rng_seed_stream(&rng, seed, label);
        int rc = s->n_faces ? tcb_sample_surface(tcb_seq_frame(s, f), s->faces, s->n_faces, pool_size, &rng,
                                                 pools + (size_t)f * pool_size * 3, err)
                            : sample_points(s, f, pool_size, &rng, pools + (size_t)f * pool_size * 3);
        if (rc) {
            free(pools);
            tcb_error_prefix(err, "sequence %s frame %d: ", s->name, f);
            return rc;
        }
    }
    free(s->pools);
    s->pools = pools;
    s->pool_size = pool_size;
    return TCB_OK;
}

int tcb_sequence_prepare(tcb_sequence *s, const tcb_load_opts *o, tcb_error *err)
{
    int rc = tcb_sequence_normalize(s, o->norm, err);
    if (!rc && o->align_samples > 0) {
        int *step = malloc((size_t)s->n_frames * sizeof *step);
        rc = step ? tcb_align_yaw(s, o->align_samples, o->pool_seed, step, NULL, err)
                  : tcb_fail(err, TCB_ERR_NOMEM, "sequence %s: out of memory", s->name);
        if (!rc) rc = tcb_sequence_apply_yaw(s, step, err);
        free(step);
    }
    if (!rc) rc = tcb_sequence_sample_pools(s, o->pool_size ? o->pool_size : TCB_DEFAULT_POOL_SIZE, o->pool_seed, err);
    return rc;
}

static void copy_point(float *dst, const float *pool, uint32_t k)
{
    memcpy(dst, pool + 3 * (size_t)k, 3 * sizeof(float));
}

int tcb_sequence_draw_points(const tcb_sequence *s, int f, int n, int with_replacement,
                             tcb_rng *rng, float *out, tcb_error *err)
{
    if (f < 0 || f >= s->n_frames)
        return tcb_fail(err, TCB_ERR_INPUT, "sequence %s: frame %d out of range (%d frames)", s->name, f,
                        s->n_frames);
    if (!s->pools) return tcb_fail(err, TCB_ERR_INTERNAL, "sequence %s: no point pools sampled", s->name);
    if (n < 0 || (!with_replacement && n > s->pool_size))
        return tcb_fail(err, TCB_ERR_INPUT, "sequence %s: cannot draw %d points %s replacement from a pool of %d",
                        s->name, n, with_replacement ? "with" : "without", s->pool_size);
    const float *pool = tcb_seq_pool(s, f);
    if (with_replacement) {
        for (int i = 0; i < n; i++) copy_point(out + 3 * (size_t)i, pool, tcb_rng_below(rng, (uint32_t)s->pool_size));
        return TCB_OK;
    }
    /* The first n entries of a uniform permutation, by a Fisher–Yates
     * shuffle stopped after n steps. */
    uint32_t *idx = malloc((size_t)s->pool_size * sizeof *idx);
    if (!idx) return tcb_fail(err, TCB_ERR_NOMEM, "sequence %s: out of memory", s->name);
    for (int i = 0; i < s->pool_size; i++) idx[i] = (uint32_t)i;
    for (int i = 0; i < n; i++) {
        uint32_t j = (uint32_t)i + tcb_rng_below(rng, (uint32_t)(s->pool_size - i));
        uint32_t t = idx[i];
        idx[i] = idx[j];
        idx[j] = t;
        copy_point(out + 3 * (size_t)i, pool, idx[i]);
    }
    free(idx);
    return TCB_OK;
}
