/* The two styles of `tcbench frames` (tcb/frames.h), each in its own file;
 * views/frames.c picks the cell, the frames and the style. Private to
 * views/. */
#ifndef TCB_VIEWS_FRAMES_STYLE_H
#define TCB_VIEWS_FRAMES_STYLE_H

#include "harness/harness.h"
#include "tcb/rng.h"

typedef struct tcb_frames_job {
    const tcb_cell_job *cell;  /* the opened cell; its model is reopened per style */
    const int *frames;         /* [n] distinct, in range */
    int n;
    const char *dir;           /* created only once everything is computed */
} tcb_frames_job;

/* checker.png, checker.mtl, frame_<f>.obj, strip.png (views/frames_texture.c). */
int tcb_frames_texture(const tcb_frames_job *f, tcb_error *err);
/* frame_<f>.ply, strip.png (views/frames_transfer.c). */
int tcb_frames_transfer(const tcb_frames_job *f, tcb_error *err);

/* A patch of a surface is collapsed when its area is under this fraction
 * of its share of the frame's GT surface, gt_area / n_charts (a patch that
 * covers its share: 1). The slivers of quick.json's atlas rows (preset
 * tiny, 4 patches) measure 0.0003 to 0.011; a patch at 1/20 of its share
 * covers too little of the body to be a piece of its surface. */
#define TCB_FRAMES_COLLAPSED 0.05

/* Marks collapsed[c] for each collapsed chart c of m (the surface of a
 * frame of GT area gt_area), their count in *n (0 for a mesh without
 * charts). (views/frames_collapse.c) */
int tcb_frames_collapsed(const tcb_uv_mesh *m, double gt_area, unsigned char *collapsed, int *n, tcb_error *err);

/* The cell seed's stream "frames/<dataset>/<sequence>/<i>" (j < 0: the
 * surface of frame i) or ".../<i>/<j>" (transfer i -> j). (views/frames.c) */
void tcb_frames_rng(const tcb_cell_job *cell, int i, int j, tcb_rng *rng);

#endif
