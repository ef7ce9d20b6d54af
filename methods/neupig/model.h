/* Neu-PiG's deformation model (Neural Preconditioned Grids, CVPR 2026;
 * github vc-bonn/neu-pig @ f5e1c1c: src/optimization.py, src/opt_run.py,
 * configs/method/fit_.json; grids from vc-bonn/pcgrid): a fixed template
 * (nv vertices, their normals) moved rigidly per vertex and frame.
 *
 *   position grid  levels l = 0 … L−1 of r_l = base_res + l·res_step nodes
 *                  per axis, F features; values v_l = M_l⁻¹ u_l with
 *                  λ_l = λ·growth^l (neural/sobolev.h); sampled at the
 *                  template's vertices, averaged over levels, tanh
 *   normal grid    one level of normal_res nodes, Fn features, λ_n, sampled
 *                  at the template's vertex normals, tanh
 *   time           2J Fourier features of t̃ = t / (T − 1) (neural/fourier_time.h)
 *   MLP            [F + Fn + 2J] → H → H → 7, LeakyReLU(0.01), the last
 *                  layer zero at the start (identity motion)
 *   motion         rotation from a quaternion, translation tanh(0.1·d)
 *                  (neural/rigid.h): X_t[v] = R x_v + t
 *   loss           mean_t c_t·CD_t + edge_weight·mean |len − len_template|
 *                  (methods/neupig/loss.h)
 * The optimiser works on u (the grids' preconditioned parameters) and the
 * MLP's weights; the grids start at zero.
 *
 * Parameters, one flat float vector: level 0's u [r_0³][F], …, level L−1's,
 * the normal grid's u [r_n³][Fn], then W1 b1 W2 b2 W3 b3 (PyTorch's
 * Linear layout). */
#ifndef TCB_NEUPIG_MODEL_H
#define TCB_NEUPIG_MODEL_H

#include <stddef.h>
#include <stdint.h>

#include "neural/layers.h"
#include "neural/sobolev.h"
#include "tcb/error.h"
#include "tcb/nn.h"
#include "tcb/rng.h"

#define TCB_NEUPIG_MAX_LEVELS 16
#define TCB_NEUPIG_MAX_FRAMES 4096 /* the per-frame confidences sit on the stack */
#define TCB_NEUPIG_LEAKY_SLOPE 0.01f

typedef struct tcb_neupig_arch {
    int levels, base_res, res_step, features;  /* 8, 2, 3, 30 */
    int normal_res, normal_features;            /* 4, 2 */
    int time_freqs;                             /* J = 4: 8 time features */
    int hidden;                                 /* 512 */
    double lambda, lambda_growth, normal_lambda; /* 0.4, 1.5, 0.4 */
    double edge_weight;                         /* 100 */
    double welsch_alpha;                        /* 0.3 */
    tcb_sobolev_laplacian laplacian;            /* the grids' Laplacian: pcgrid's 2D − A */
} tcb_neupig_arch;

/* The reference's architecture and loss weights (fit_.json). */
tcb_neupig_arch tcb_neupig_arch_reference(void);

typedef struct tcb_neupig_model {
    tcb_neupig_arch a;
    int grids;                 /* levels + 1: the normal grid last */
    int res[TCB_NEUPIG_MAX_LEVELS + 1], width[TCB_NEUPIG_MAX_LEVELS + 1];
    size_t grid_off[TCB_NEUPIG_MAX_LEVELS + 2]; /* [grids] = the MLP's offset */
    size_t n_params;
    tcb_sobolev sobolev[TCB_NEUPIG_MAX_LEVELS + 1];
} tcb_neupig_model;

int tcb_neupig_model_init(tcb_neupig_model *m, const tcb_neupig_arch *a, tcb_error *err);
void tcb_neupig_model_free(tcb_neupig_model *m);

/* The MLP's layers viewed inside params (or a gradient vector). */
void tcb_neupig_mlp_view(const tcb_neupig_model *m, float *params, tcb_linear layers[3]);

/* Starting parameters: grids zero, hidden layers PyTorch's default init
 * from rng, the last layer zero. */
void tcb_neupig_params_init(const tcb_neupig_model *m, float *params, tcb_rng *rng);

/* What one optimisation step sees (owned by the caller). */
typedef struct tcb_neupig_problem {
    int nv;
    const float *verts, *normals;     /* [nv][3] the template, in the grids' cube [−1, 1]³ */
    int ne;
    const int32_t *edges;             /* [ne][2] undirected */
    const float *edge_len;            /* [ne] the template's */
    int T;                            /* frames */
    const float *const *points;       /* [T] → [n_points[t]][3] */
    const int *n_points;
    const tcb_nn *const *points_index; /* [T] indexes of those points */
    int key;                          /* keyframe */
} tcb_neupig_problem;

typedef struct tcb_neupig_loss {
    double total, chamfer, edge;      /* total = chamfer + edge */
} tcb_neupig_loss;

/* The buffers of one loss-and-gradient evaluation at a problem's sizes,
 * rows = T·nv: allocated once, so that an epoch allocates nothing (the
 * paper preset's activations are ~0.4 GB; mapped afresh each epoch, their
 * page faults were a third of the step). */
typedef struct tcb_neupig_work {
    int T, nv, rows;
    float *feat_p, *feat_n;       /* [nv][F], [nv][Fn] after tanh */
    float *x0, *h1, *h2, *o;      /* MLP input [rows][in], hidden [rows][H] ×2, output [rows][7] */
    float *X, *dX;                /* [rows][3]: the moved template, the loss's gradient in it */
    float *dout, *dh, *dx0;       /* the backward's [rows][7], [rows][H], [rows][in] */
    float *dfeat_p, *dfeat_n;     /* [nv][F], [nv][Fn] */
    float *values;                /* one grid's values, the largest grid's size */
    double *scratch;              /* the Sobolev solve's, as large */
    double *cd;                   /* [T] each frame's CD */
} tcb_neupig_work;

int tcb_neupig_work_init(tcb_neupig_work *w, const tcb_neupig_model *m, const tcb_neupig_problem *p,
                         tcb_error *err);
void tcb_neupig_work_free(tcb_neupig_work *w);

/* X [T][nv][3]: the template moved into every frame, through w (made for
 * p's sizes: the trainer's, so a read-out allocates nothing either). */
int tcb_neupig_deform(const tcb_neupig_model *m, const float *params, const tcb_neupig_problem *p,
                      tcb_neupig_work *w, float *X, tcb_error *err);

/* The loss at (epoch of epochs) and its gradient, grads [n_params]
 * (overwritten), through w (made for p's sizes); each frame's CD is left
 * in w->cd. */
int tcb_neupig_loss_grad(const tcb_neupig_model *m, const float *params,
                         const tcb_neupig_problem *p, tcb_neupig_work *w, long long epoch,
                         long long epochs, tcb_neupig_loss *out, float *grads, tcb_error *err);

#endif
