/* DynoSurf's deformer: the template carried to each frame by K control
 * points, each with a rotation and a translation per frame, blended by
 * learned weights (github yaoyx689/DynoSurf @ a2b7324:
 * code/model/deformer_network.py ControlPts_deformer L45-257,
 * code/LieAlgebra/so3.py; confs/base.conf [ControlPts_Deformer]).
 *
 *   c_k                 K = 30 control points, learned; initially the
 *                       farthest points of the grid's vertices from a
 *                       random start (farthest_point_sample)
 *   transform(t, k)     e = posenc([t, c_k], 2 frequencies)       [20]
 *                       o = MLP_T(e), ReLU, 128 wide, 6 layers    [6]
 *                       R_k(t) = exp(o[0:3]) (so(3)), T_k(t) = o[3:6]
 *                       t the raw frame index, as the reference's
 *   blend(x)            g_k = MLP_W([x, x − c_k]), ReLU, 128 wide, 6 layers
 *                       w(x) = softmax_k g
 *   deform(x, t)        Σ_k w_k(x) (R_k(t) x + T_k(t))   (rotations about
 *                       the origin: the reference's rot_around_nodes = 0)
 *
 * Parameters in one flat buffer: control points [K][3], then MLP_T, then
 * MLP_W (the tail, which the blend pretraining alone updates). */
#ifndef TCB_DYNOSURF_DEFORMER_H
#define TCB_DYNOSURF_DEFORMER_H

#include <stddef.h>

#include "neural/mlp.h"
#include "tcb/error.h"

#define DYNO_CONTROL_POINTS 30
#define DYNO_DEFORM_WIDTH 128
#define DYNO_DEFORM_LAYERS 6
#define DYNO_TIME_FREQS 2
#define DYNO_TRANSFORM_IN 20 /* 4 · (1 + 2 · DYNO_TIME_FREQS) */
#define DYNO_TRANSFORM_OUT 6
#define DYNO_BLEND_IN 6
#define DYNO_BLEND_SIGMA 0.1 /* the Gaussian the blend weights start as */

typedef struct dyno_deformer {
    float *control; /* [K][3] */
    tcb_mlp transform, blend;
} dyno_deformer;

size_t dyno_deformer_size(void);
/* The offset of MLP_W's weights in the buffer (its size: the rest). */
size_t dyno_deformer_blend_offset(void);
void dyno_deformer_bind(dyno_deformer *d, float *params);

struct tcb_rng;
/* PyTorch's Linear initialisation of both networks and the control points
 * by farthest-point sampling over the grid's vertices [nv][3]. */
int dyno_deformer_init(const dyno_deformer *d, const float *grid_verts, int nv, struct tcb_rng *rng, tcb_error *err);

/* The blend weights of up to `capacity` points, and their backward. */
typedef struct dyno_blend {
    int capacity, n;
    float *in;    /* [n·K][6]: (x, x − c_k) */
    float *logit; /* [n·K] */
    float *w;     /* [n][K] */
    float *dw, *dlogit, *din; /* [n][K], [n·K], [n·K][6] */
    tcb_mlp_acts acts;
} dyno_blend;

int dyno_blend_alloc(dyno_blend *b, int capacity, tcb_error *err);
void dyno_blend_free(dyno_blend *b);
void dyno_blend_forward(const dyno_deformer *d, dyno_blend *b, const float *x, int n);
/* grad's MLP_W += and grad's control points += the gradient through the
 * weights for b->dw [n][K] = ∂L/∂w (the caller's), after the forward that
 * filled b. */
void dyno_blend_backward(const dyno_deformer *d, const dyno_deformer *grad, dyno_blend *b);

/* The Gaussian blend weights the network is pretrained to:
 * w [n][K] = softmax_k(−|x − c_k|² / (2σ²)). */
void dyno_blend_gaussian(const dyno_deformer *d, const float *x, int n, float *w);

/* The blend pretraining's loss, MSELoss(w(x), gaussian(x)) over x [n][3]
 * (the reference draws 1 024 points U[−½, ½]³ each step); grad's MLP_W
 * (and control points, which the pretraining leaves) += its gradient. */
double dyno_blend_pretrain_loss(const dyno_deformer *d, const dyno_deformer *grad, dyno_blend *b, const float *x,
                                int n);

/* The transforms of up to `capacity` frames, and their backward. */
typedef struct dyno_transforms {
    int capacity, n_frames;
    float *tc;  /* [F·K][4]: (t, c_k) */
    float *in;  /* [F·K][20]: its encoding */
    float *raw; /* [F·K][6]: axis-angle, translation */
    float *R;   /* [F·K][9] */
    float *dR, *draw, *din, *dtc;
    tcb_mlp_acts acts;
} dyno_transforms;

int dyno_transforms_alloc(dyno_transforms *tr, int capacity, tcb_error *err);
void dyno_transforms_free(dyno_transforms *tr);
/* For the frame indices frames[0..n) (raw indices, as t). */
void dyno_transforms_forward(const dyno_deformer *d, dyno_transforms *tr, const int *frames, int n);
/* Backward from tr->dR [F·K][9] and tr->draw [F·K][6] (the caller fills
 * both: the translations' and any direct gradient of raw); grad's MLP_T
 * and control points +=. Overwrites tr->draw's rotation part. */
void dyno_transforms_backward(const dyno_deformer *d, const dyno_deformer *grad, dyno_transforms *tr);

/* X [n][3] = deform(x, t) for one frame's R [K][9] and raw [K][6]. */
void dyno_deform_apply(const float *x, int n, const float *w, const float *R, const float *raw, float *X);
/* From dX [n][3]: dR [K][9] +=, draw's translations [K][6] +=, dw [n][K] +=. */
void dyno_deform_apply_backward(const float *x, int n, const float *w, const float *R, const float *raw,
                                const float *dX, float *dR, float *draw, float *dw);

#endif
