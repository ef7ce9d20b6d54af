/* What the pcgrid methods (Neu-PiG, PDG) share around their optimisation:
 * the inputs they draw — every frame's cloud from the sequence's pools,
 * mapped into the grids' cube and indexed — and the read-out of a fitted
 * model, the template carried into every frame: a source point located on
 * frame i's mesh and carried to the same barycentric point of frame j's
 * (tcb/locate.h), surface samples of a frame's mesh, and the mesh itself
 * (tcb/method.h's transfer, reconstruct and surface). Everything inside is
 * in the cube; what leaves goes back to the sequence's coordinates. */
#ifndef TCB_PCGRID_FITTED_H
#define TCB_PCGRID_FITTED_H

#include <stdint.h>

#include "methods/pcgrid/prepare.h"
#include "tcb/error.h"
#include "tcb/mesh.h"
#include "tcb/method.h"
#include "tcb/nn.h"
#include "tcb/rng.h"
#include "tcb/sequence.h"

/* Every frame's cloud, in the cube, and its k-NN index. */
typedef struct tcb_pcgrid_clouds {
    int T;
    float **clouds;   /* [T] → [n[t]][3] */
    int *n;
    tcb_nn **index;   /* [T] */
} tcb_pcgrid_clouds;

/* The map of the drawn clouds into a method's frame (tcb_pcgrid_frame_map_of:
 * the pcgrid cube). */
typedef int (*tcb_pcgrid_map_fn)(const float *const *clouds, const int *n, int T, tcb_pcgrid_frame_map *map,
                                 tcb_error *err);

/* `points` points a frame drawn from seq's pools (as the sequence draws:
 * with or without replacement) from the stream (seed, stream), the map of
 * all of them (map_of; NULL: into the cube) in *map, and the mapped clouds
 * indexed. */
int tcb_pcgrid_clouds_draw(const tcb_sequence *seq, int points, uint64_t seed, const char *stream,
                           tcb_pcgrid_map_fn map_of, tcb_pcgrid_frame_map *map, tcb_pcgrid_clouds *out,
                           tcb_error *err);
void tcb_pcgrid_clouds_free(tcb_pcgrid_clouds *c);

/* A fitted model: the template and its vertices in every frame. */
typedef struct tcb_pcgrid_fitted {
    const char *method;        /* for messages */
    tcb_pcgrid_frame_map map;
    tcb_mesh template_mesh;    /* its faces are every frame's */
    float *deformed;           /* [n_frames][nv][3]; NULL before a fit or load */
    int n_frames;
} tcb_pcgrid_fitted;

/* Frees the template and the frames (the map and method stay). */
void tcb_pcgrid_fitted_release(tcb_pcgrid_fitted *f);

/* tcb_method_ops.transfer, .reconstruct (n_points samples of the frame's
 * mesh) and .surface over the fitted frames. */
int tcb_pcgrid_transfer(const tcb_pcgrid_fitted *f, const tcb_sequence *seq, int i, int j, const float *src, int n,
                        float *out, tcb_error *err);
int tcb_pcgrid_reconstruct(const tcb_pcgrid_fitted *f, const tcb_sequence *seq, int i, int j, int frame,
                           int n_points, tcb_rng *rng, float **pts, int *n, tcb_error *err);
int tcb_pcgrid_surface(const tcb_pcgrid_fitted *f, const tcb_sequence *seq, int frame, tcb_uv_mesh *out,
                       tcb_error *err);

#endif
