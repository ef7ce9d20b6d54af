/* DynoSurf's stage 2: the deformer fitted to every frame at once, the
 * template frozen (github yaoyx689/DynoSurf @ a2b7324: code/trainer.py
 * joint_optimize_all_frames L101-138, code/loss.py calc_joint_loss L49-86,
 * robust Chamfer L97-139, calc_surface_smooth_loss L143-160,
 * calc_robust_sdf_sign_loss L234-266; confs/base.conf [JointOptimize]).
 * Every step, for all F frames (X_t the template's vertices carried to
 * frame t, Y_t the deformed grid vertices of 10 000 picked afresh, ŝ their
 * template SDF):
 *
 *   500 · chamfer     mean_t of the robust Chamfer (neural/robust_chamfer)
 *                     between 10 000 samples of the mesh (X_t, faces) and
 *                     frame t's points
 *   0.001 · normal    mean_t of its normal term
 *   1 · identity      Σ raw_k(key)²: the keyframe's 30 transforms stay at
 *                     the identity
 *   100 · sdf_sign    mean_{t,n} ρ_tn |σ(100 ŝ_n) − σ(100 s_t(Y_tn))|, s_t
 *                     frame t's approximate SDF (neural/approx_sdf), ρ the
 *                     softmax over frames of −s²/(2 · 0.1²), held constant
 *   1000 · smooth     Σ over (t, u) for u in t's neighbours {t − 1, t + 1}
 *                     (clamped to the clip) and over each face's three
 *                     edges (a, b) of |D_a − D_b|², D = X_u − X_t, over
 *                     3 · faces: each edge's change between adjacent frames
 *
 * The gradient goes to the deformer alone (the reference's Decoder has
 * requires_grad off in this stage). */
#ifndef TCB_DYNOSURF_MOTION_H
#define TCB_DYNOSURF_MOTION_H

#include <stdint.h>

#include "methods/dynosurf/deformer.h"
#include "neural/mesh_sample.h"
#include "tcb/error.h"
#include "tcb/nn.h"

#define DYNO_MOTION_SAMPLES 10000
#define DYNO_GRID_SAMPLES 10000
#define DYNO_SIGMOID_SCALE 100.0
#define DYNO_FUSION_THRES 0.1

struct tcb_rng;

/* The terms' weights: the reference's are DYNO_MOTION_WEIGHTS. */
typedef struct dyno_motion_weights {
    double chamfer, normal, identity, sdf_sign, smooth;
} dyno_motion_weights;
#define DYNO_MOTION_WEIGHTS ((dyno_motion_weights){500.0, 0.001, 1.0, 100.0, 1000.0})

/* What stage 2 reads, the caller's for the fit's life. */
typedef struct dyno_motion_data {
    int n_frames, key;
    const float *const *pts, *const *normals; /* frame t's normalised points and normals [n_pts[t]][3] */
    const int *n_pts;
    const tcb_nn *const *index;               /* over each frame's points */
    const float *template_verts;              /* [n_template][3] */
    int n_template;
    const int32_t *faces;                     /* [n_faces][3] */
    int n_faces;
    const float *grid_v, *grid_sdf;           /* the deformed grid [n_grid][3] and its SDF [n_grid] */
    int n_grid;
    int n_samples, n_grid_samples;            /* DYNO_MOTION_SAMPLES, DYNO_GRID_SAMPLES (capped at n_grid) */
    dyno_motion_weights weights;
} dyno_motion_data;

typedef struct dyno_motion_fit {
    dyno_motion_data data;
    int *frames;             /* 0 … F − 1 */
    int32_t *perm;           /* [n_grid]: this step's picks are its first n_grid_samples */
    dyno_blend bt, bg;       /* blend weights of the template and of the picks */
    dyno_transforms tr;
    float *X, *dX;           /* [F][n_template][3] */
    float *y, *yhat;         /* the picks [g][3] and their SDF [g] */
    float *Y, *dY;           /* [F][g][3] */
    float *s, *ds;           /* [F][g] */
    int32_t *nbr;            /* [F][g][TCB_APPROX_SDF_K] */
    tcb_mesh_draw *draws;    /* [F][n_samples]: this step's surface samples */
    int n_scratch;           /* the threads that take frames side by side, one scratch each */
    float *xs, *nxs, *dxs, *dnxs; /* per thread: samples, normals and their gradients [n_samples][3] */
    float *face_grad;        /* per thread: [n_faces][3] */
    double *frame_cd, *frame_normal; /* [F]: each frame's terms, summed in frame order */
} dyno_motion_fit;

int dyno_motion_fit_init(dyno_motion_fit *f, const dyno_motion_data *data, tcb_error *err);
void dyno_motion_fit_free(dyno_motion_fit *f);

typedef struct dyno_motion_terms {
    double chamfer, normal, identity, sdf_sign, smooth, total;
} dyno_motion_terms;

/* The loss with picks and surface samples drawn from rng; grad += its
 * gradient in the deformer's parameters. */
int dyno_motion_loss(dyno_motion_fit *f, const dyno_deformer *d, const dyno_deformer *grad, struct tcb_rng *rng,
                     dyno_motion_terms *t, tcb_error *err);

/* What each frame adds to a step, for the dry run's `frame` unit: frame
 * u's deformation of the template and the picks, its surface samples
 * (from rng), robust Chamfer and normal terms, approximate SDF forward and
 * backward, and its share of the backward through the deformation, on the
 * blend weights, transforms and picks of the last dyno_motion_loss (which
 * must have run). It moves no parameter: the next loss recomputes all it
 * writes. */
int dyno_motion_frame_cost(dyno_motion_fit *f, struct tcb_rng *rng, int u, tcb_error *err);

/* The template's vertices carried to every frame: X [F][n_template][3]. */
void dyno_motion_frames(dyno_motion_fit *f, const dyno_deformer *d, float *X);

#endif
