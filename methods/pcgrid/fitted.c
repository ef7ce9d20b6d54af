/* The pcgrid methods' inputs and read-out (methods/pcgrid/fitted.h). */
#include "methods/pcgrid/fitted.h"

#include <stdlib.h>
#include <string.h>

#include "tcb/geometry.h"
#include "tcb/locate.h"

int tcb_pcgrid_clouds_draw(const tcb_sequence *seq, int points, uint64_t seed, const char *stream,
                           tcb_pcgrid_map_fn map_of, tcb_pcgrid_frame_map *map, tcb_pcgrid_clouds *out,
                           tcb_error *err)
{
    memset(out, 0, sizeof *out);
    out->T = seq->n_frames;
    out->clouds = calloc((size_t)out->T, sizeof *out->clouds);
    out->n = calloc((size_t)out->T, sizeof *out->n);
    out->index = calloc((size_t)out->T, sizeof *out->index);
    if (!out->clouds || !out->n || !out->index) return tcb_fail(err, TCB_ERR_NOMEM, "out of memory");
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, seed, stream);
    int rc = TCB_OK;
    for (int t = 0; !rc && t < out->T; t++) {
        out->n[t] = points;
        if (!(out->clouds[t] = malloc((size_t)points * 3 * sizeof(float))))
            return tcb_fail(err, TCB_ERR_NOMEM, "out of memory");
        rc = tcb_sequence_draw_points(seq, t, points, seq->draw_with_replacement, &rng, out->clouds[t], err);
    }
    if (!rc) rc = (map_of ? map_of : tcb_pcgrid_frame_map_of)((const float *const *)out->clouds, out->n, out->T, map, err);
    for (int t = 0; !rc && t < out->T; t++) {
        tcb_pcgrid_map_points(map, out->clouds[t], out->n[t], out->clouds[t]);
        rc = tcb_nn_build(out->clouds[t], out->n[t], &out->index[t], err);
    }
    return rc;
}

void tcb_pcgrid_clouds_free(tcb_pcgrid_clouds *c)
{
    for (int t = 0; c->clouds && t < c->T; t++) free(c->clouds[t]), tcb_nn_free(c->index[t]);
    free(c->clouds), free(c->n), free(c->index);
    memset(c, 0, sizeof *c);
}

void tcb_pcgrid_fitted_release(tcb_pcgrid_fitted *f)
{
    free(f->deformed);
    f->deformed = NULL;
    f->n_frames = 0;
    tcb_mesh_free(&f->template_mesh);
}

static int check_frames(const tcb_pcgrid_fitted *f, const tcb_sequence *seq, int i, int j, tcb_error *err)
{
    if (!f->deformed) return tcb_fail(err, TCB_ERR_INTERNAL, "%s: evaluation before fit or load", f->method);
    if (i < 0 || j < 0 || i >= f->n_frames || j >= f->n_frames || seq->n_frames != f->n_frames)
        return tcb_fail(err, TCB_ERR_INPUT, "%s: pair %d->%d outside frames 0..%d of the fitted sequence", f->method,
                        i, j, f->n_frames - 1);
    return TCB_OK;
}

static const float *frame_verts(const tcb_pcgrid_fitted *f, int frame)
{
    return f->deformed + (size_t)frame * (size_t)f->template_mesh.n_verts * 3;
}

int tcb_pcgrid_transfer(const tcb_pcgrid_fitted *f, const tcb_sequence *seq, int i, int j, const float *src, int n,
                        float *out, tcb_error *err)
{
    int rc = check_frames(f, seq, i, j, err);
    if (rc) return rc;
    const tcb_mesh *t = &f->template_mesh;
    tcb_surface_point *loc = malloc((size_t)n * sizeof *loc);
    if (!loc) return tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", f->method);
    tcb_pcgrid_map_points(&f->map, src, n, out);
    rc = tcb_mesh_locate(frame_verts(f, i), t->n_verts, t->faces, t->n_faces, out, n, loc, NULL, err);
    if (!rc) {
        tcb_surface_points(frame_verts(f, j), t->faces, loc, n, out);
        tcb_pcgrid_unmap_points(&f->map, out, n);
    }
    free(loc);
    return rc;
}

int tcb_pcgrid_reconstruct(const tcb_pcgrid_fitted *f, const tcb_sequence *seq, int i, int j, int frame,
                           int n_points, tcb_rng *rng, float **pts, int *n, tcb_error *err)
{
    *pts = NULL;
    int rc = check_frames(f, seq, i, j, err);
    if (rc) return rc;
    const tcb_mesh *t = &f->template_mesh;
    if (!(*pts = malloc((size_t)n_points * 3 * sizeof **pts)))
        return tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", f->method);
    rc = tcb_sample_surface(frame_verts(f, frame), t->faces, t->n_faces, n_points, rng, *pts, err);
    if (rc) {
        free(*pts), *pts = NULL;
        return rc;
    }
    tcb_pcgrid_unmap_points(&f->map, *pts, n_points);
    *n = n_points;
    return TCB_OK;
}

int tcb_pcgrid_surface(const tcb_pcgrid_fitted *f, const tcb_sequence *seq, int frame, tcb_uv_mesh *out,
                       tcb_error *err)
{
    const tcb_uv_mesh none = {0, 0, 0, NULL, NULL, NULL, NULL};
    *out = none;
    int rc = check_frames(f, seq, frame, frame, err);
    if (rc) return rc;
    const tcb_mesh *t = &f->template_mesh;
    size_t vbytes = (size_t)t->n_verts * 3 * sizeof *out->verts, fbytes = (size_t)t->n_faces * 3 * sizeof *out->faces;
    out->verts = malloc(vbytes), out->faces = malloc(fbytes);
    if (!out->verts || !out->faces) {
        tcb_uv_mesh_free(out);
        return tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", f->method);
    }
    memcpy(out->verts, frame_verts(f, frame), vbytes);
    tcb_pcgrid_unmap_points(&f->map, out->verts, t->n_verts);
    memcpy(out->faces, t->faces, fbytes);
    out->n_verts = t->n_verts, out->n_faces = t->n_faces;
    return TCB_OK;
}
