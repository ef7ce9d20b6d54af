/* A row of flat-shaded mesh views in one PNG (cairo), for `tcbench
 * inspect` and `tcbench frames`. Private to views/. */
#ifndef TCB_VIEWS_RENDER_H
#define TCB_VIEWS_RENDER_H

#include <cairo.h>
#include <stdint.h>

#include "tcb/error.h"

typedef struct tcb_render_panel {
    const char *title;
    const float *verts;   /* [nv][3] */
    const uint8_t *rgb;   /* [nv][3] vertex colours; a face shows their mean */
    const uint8_t *face_rgb; /* [nf][3] or NULL: each face's own colour instead
                              * (a texture looked up per face, which a mean of
                              * vertex colours would blur across checks) */
} tcb_render_panel;

/* Panels of meshes sharing `faces` [nf][3] and vertex count nv (nf 0: points
 * alone, each vertex a dot in its colour), drawn side
 * by side with one orthographic camera: looking along the axis in which
 * `ref` [n_ref][3] is thinnest (the side of an animal), y up where y is not
 * that axis, faces back to front, shaded by their slant to the viewer.
 * With `colorbar_max` > 0 the last panel gets a viridis scale from 0 to
 * it. Written atomically to `path`. */
int tcb_render_panels(const char *path, const tcb_render_panel *panels, int n_panels, int nv,
                      const int32_t *faces, int nf, const float *ref, int n_ref, double colorbar_max,
                      tcb_error *err);

/* Writes `surface` as a PNG at `path` atomically and destroys it (also on
 * failure); a surface in an error state is reported, not written. */
int tcb_render_save_png(cairo_surface_t *surface, const char *path, tcb_error *err);

#endif
