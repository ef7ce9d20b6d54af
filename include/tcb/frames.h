/* tcbench — a few frames of a fitted cell as the picture papers of this
 * field show: `tcbench frames`.
 *
 * Two styles. A method whose table has `surface` (the atlas family) is
 * drawn as its own reconstruction of each chosen frame, textured with one
 * checkerboard in UV space: the same texture in every frame, so a patch
 * that slides over the body, flips or shrinks shows it at a glance:
 *
 *   frame_<f>.obj   the surface of frame f (v, vt, f v/vt; mtllib
 *                   checker.mtl), normalized coordinates
 *   checker.mtl     one material, map_Kd checker.png
 *   checker.png     the texture: chart c's square in cell c of a grid,
 *                   8 x 8 checks in two tones of the chart's hue, the check
 *                   at the chart's (0, 0) white (views/checker.h)
 *   strip.png       the frames side by side, one camera, each face in the
 *                   texture's colour at its UV centroid; a frame whose
 *                   patches collapsed (area under 5 % of their share of
 *                   the frame's GT area) is titled so, and a warning
 *                   through the reporter lists them
 *
 * A surface without charts (tcb/method.h; neupig's template moved into
 * each frame) has no texture: each vertex keeps the colour of its place in
 * the first chosen frame (as inspect's body-place colours) in every frame:
 *
 *   frame_<f>.ply   the surface of frame f in those colours
 *   strip.png       the frames side by side, one camera
 *
 * Every other method (style "transfer") is drawn as its correspondences:
 * the first chosen frame i on its GT mesh with vertices coloured by their
 * place on the body, and each other chosen frame j on its GT mesh with
 * vertex k in the colour of the vertex the method's transfer i -> j sent
 * it to (as inspect's transfer.ply): where a colour is out of place, the
 * method went wrong:
 *
 *   frame_<f>.ply   the GT mesh of frame f in those colours
 *   strip.png       the frames side by side, one camera
 *
 * The fitted model is reopened from the cell's checkpoint as `inspect`
 * does (never refitted); input clouds come from the cell seed's streams
 * "frames/<dataset>/<sequence>/<f>" (surface of frame f) and
 * "frames/<dataset>/<sequence>/<i>/<j>" (transfer i -> j), so the pictures
 * are reproducible. All files are written atomically, after every frame
 * was computed and checked. */
#ifndef TCB_FRAMES_H
#define TCB_FRAMES_H

#include <stdio.h>

#include "tcb/error.h"
#include "tcb/progress.h"

#ifdef __cplusplus
extern "C" {
#endif

#define TCB_FRAMES_MAX 16     /* frames in one strip */
#define TCB_FRAMES_DEFAULT 5  /* evenly spaced frames when none are named */

typedef enum tcb_frames_style {
    TCB_FRAMES_AUTO,     /* texture when the method has `surface`, else transfer */
    TCB_FRAMES_TEXTURE,  /* an error for a method without `surface` */
    TCB_FRAMES_TRANSFER,
} tcb_frames_style;

typedef struct tcb_frames_opts {
    const char *run_dir;
    const char *method;       /* the config's label */
    const int *frames;        /* [n_frames] distinct frame numbers, or NULL: */
    int n_frames;
    int count;                /* ... `count` frames evenly spaced from the first to the
                               * last (<= 0: TCB_FRAMES_DEFAULT, or all when fewer) */
    int seed;                 /* < 0: the config's first seed */
    const char *sequence;     /* "dataset/sequence"; NULL when the config has only one */
    const char *out_dir;      /* NULL: <run>/frames/<dataset>/<sequence>/<method>/seed_<s> */
    int threads;              /* <= 0: the config's */
    tcb_frames_style style;
    tcb_reporter reporter;
} tcb_frames_opts;

/* Writes the files above and a short account to `out` (NULL: none); the
 * output directory's path to out_path[TCB_PATH_MAX] when non-NULL. */
int tcb_frames(const tcb_frames_opts *o, FILE *out, char *out_path, tcb_error *err);

#ifdef __cplusplus
}
#endif
#endif
