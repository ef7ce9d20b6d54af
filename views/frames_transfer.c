/* `tcbench frames` for any method: its transfer from the first chosen frame
 * to each other one, drawn on the GT meshes in body-place colours
 * (tcb/frames.h). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tcb/frames.h"
#include "tcb/fsutil.h"
#include "tcb/geometry.h"
#include "tcb/mesh_io.h"
#include "views/colormap.h"
#include "views/frames_style.h"
#include "views/render.h"

typedef struct transfers {
    const tcb_frames_job *f;
    float *moved; /* [f->n][nv][3]: slot k the transfer of frame frames[0] to frames[k]; slot 0 unused */
} transfers;

static int transfer_frames(void *ctx, void *self, tcb_error *merr)
{
    transfers *t = ctx;
    const tcb_frames_job *f = t->f;
    const tcb_sequence *seq = f->cell->seq;
    size_t nv = (size_t)seq->n_verts;
    int i = f->frames[0], pairs[2 * TCB_FRAMES_MAX];
    for (int k = 1; k < f->n; k++) pairs[2 * (k - 1)] = i, pairs[2 * (k - 1) + 1] = f->frames[k];
    /* A batch method (the external one) computes them all here. */
    int rc = tcb_cell_prepare_pairs(f->cell, self, pairs, 0, f->n - 1, merr);
    for (int k = 1; !rc && k < f->n; k++) {
        int j = f->frames[k];
        float *out = t->moved + (size_t)k * nv * 3;
        tcb_rng rng;
        tcb_frames_rng(f->cell, i, j, &rng);
        rc = f->cell->ops->transfer(self, seq, i, j, tcb_seq_frame(seq, i), seq->n_verts, out, &rng, merr);
        if (rc) tcb_error_prefix(merr, "transfer %d->%d: ", i, j);
        else if (!tcb_all_finite(out, nv * 3))
            rc = tcb_fail(merr, TCB_ERR_NUMERIC, "transfer %d->%d: returned a non-finite point", i, j);
    }
    return rc;
}

/* rgb [n][nv][3]: slot 0 the body-place colours, slot k vertex v in the
 * colour of the vertex the transfer's point for v projects to on frame j
 * (inspect's transfer.ply). */
static int colour_frames(const tcb_frames_job *f, const float *moved, uint8_t *rgb, tcb_error *err)
{
    const tcb_sequence *seq = f->cell->seq;
    size_t nv = (size_t)seq->n_verts;
    int32_t *pred = malloc(nv * sizeof *pred);
    if (!pred) return tcb_fail(err, TCB_ERR_NOMEM, "out of memory for %zu vertices", nv);
    tcb_color_by_position(tcb_seq_frame(seq, 0), seq->n_verts, rgb);
    int rc = TCB_OK;
    for (int k = 1; !rc && k < f->n; k++) {
        rc = tcb_project_to_vertices(tcb_seq_frame(seq, f->frames[k]), seq->n_verts, moved + (size_t)k * nv * 3,
                                     seq->n_verts, pred, err);
        for (size_t v = 0; !rc && v < nv; v++) memcpy(rgb + ((size_t)k * nv + v) * 3, rgb + 3 * (size_t)pred[v], 3);
    }
    free(pred);
    return rc;
}

static int write_files(const tcb_frames_job *f, const uint8_t *rgb, tcb_error *err)
{
    const tcb_sequence *seq = f->cell->seq;
    size_t nv = (size_t)seq->n_verts;
    tcb_render_panel panels[TCB_FRAMES_MAX];
    char titles[TCB_FRAMES_MAX][48], path[TCB_PATH_MAX];
    int rc = tcb_mkdirs(f->dir, err);
    for (int k = 0; !rc && k < f->n; k++) {
        const float *verts = tcb_seq_frame(seq, f->frames[k]);
        if (k) snprintf(titles[k], sizeof titles[k], "frame %d: from %d", f->frames[k], f->frames[0]);
        else snprintf(titles[k], sizeof titles[k], "frame %d (source)", f->frames[k]);
        panels[k] = (tcb_render_panel){titles[k], verts, rgb + (size_t)k * nv * 3, NULL};
        rc = tcb_path_join(path, sizeof path, err, "%s/frame_%d.ply", f->dir, f->frames[k]);
        if (!rc) rc = tcb_ply_write(path, verts, seq->n_verts, seq->faces, seq->n_faces, panels[k].rgb, err);
    }
    if (!rc) rc = tcb_path_join(path, sizeof path, err, "%s/strip.png", f->dir);
    return rc ? rc
              : tcb_render_panels(path, panels, f->n, seq->n_verts, seq->faces, seq->n_faces, tcb_seq_frame(seq, 0),
                                  seq->n_verts, 0, err);
}

int tcb_frames_transfer(const tcb_frames_job *f, tcb_error *err)
{
    size_t nv = (size_t)f->cell->seq->n_verts;
    transfers t = {f, malloc((size_t)f->n * nv * 3 * sizeof *t.moved)};
    uint8_t *rgb = malloc((size_t)f->n * nv * 3);
    int rc = !t.moved || !rgb ? tcb_fail(err, TCB_ERR_NOMEM, "out of memory for %d frames", f->n) : TCB_OK;
    if (!rc) rc = tcb_cell_use_method(f->cell, transfer_frames, &t, err);
    if (!rc) rc = colour_frames(f, t.moved, rgb, err);
    if (!rc) rc = write_files(f, rgb, err);
    free(t.moved);
    free(rgb);
    return rc;
}
