/* DynoSurf's template: the shape network pretrained to the keyframe
 * hull's signed distance, then fitted to the keyframe (stage 1), the
 * surface extracted by marching tetrahedra (github yaoyx689/DynoSurf @
 * a2b7324: code/model/dmtet_network.py pre_train_convex L45-64,
 * code/trainer.py fitting_template L74-98, code/loss.py calc_template_loss
 * L29-47, sampling L88-94, approximate_sdf_loss L177-202).
 *
 * Pretraining (1 000 iterations): mean over the grid's vertices of
 *   (sdf_i − d_i)²,  d the hull's signed distance at the undeformed vertex
 *   (tcb_convex_signed_distance; the offsets get no loss).
 * Stage 1 (5 000 iterations), on the template (MT of the deformed grid
 * v = x + tanh(o)·edge with the SDF):
 *   500 · cham + 0.001 · normal + 50 · mean_i |sdf_i − s(v_i)|
 *   cham, normal: neural/chamfer_l1 between 10 000 samples of the template
 *     (neural/mesh_sample, redrawn every step) and the keyframe's points
 *   s: the keyframe's approximate SDF (neural/approx_sdf, k 10, r 0.1) at
 *     every deformed vertex — not held constant: its gradient flows into
 *     v as the reference's does.
 * Both objectives fill the shape network's gradient; Adam is the caller's. */
#ifndef TCB_DYNOSURF_TEMPLATE_H
#define TCB_DYNOSURF_TEMPLATE_H

#include <stdint.h>

#include "methods/dynosurf/shape.h"
#include "neural/marching_tets.h"
#include "neural/mesh_sample.h"
#include "tcb/error.h"
#include "tcb/nn.h"
#include "tcb/tetmesh.h"

#define DYNO_TEMPLATE_SAMPLES 10000

/* Stage 1's weights: the reference's are DYNO_TEMPLATE_WEIGHTS. */
typedef struct dyno_template_weights {
    double chamfer, normal, sdf;
} dyno_template_weights;
#define DYNO_TEMPLATE_WEIGHTS ((dyno_template_weights){500.0, 0.001, 50.0})

struct tcb_rng;

/* What the objectives read (the caller's, held for the fit's life) and
 * their scratch. */
typedef struct dyno_template_fit {
    const tcb_tetmesh *grid;
    float edge;                 /* dyno_tet_edge_bound */
    const float *pts, *normals; /* the keyframe, normalised [n_pts][3] */
    int n_pts;
    const tcb_nn *index;        /* over pts */
    int n_samples;
    dyno_template_weights weights; /* DYNO_TEMPLATE_WEIGHTS after init */
    dyno_shape_acts acts;
    float *sdf, *v;             /* [nv], [nv][3] */
    float *dsdf, *dv, *dout;    /* [nv], [nv][3], [nv][4] */
    float *s, *ds;              /* approximate SDF at v and its gradient [nv] */
    int32_t *nbr;               /* [nv][TCB_APPROX_SDF_K] */
    tcb_mesh_draw *draws;       /* [n_samples] */
    float *x, *nx, *dx, *dnx;   /* samples and normals, their gradients [n_samples][3] */
} dyno_template_fit;

int dyno_template_fit_init(dyno_template_fit *f, const tcb_tetmesh *grid, float edge, const float *pts,
                           const float *normals, int n_pts, const tcb_nn *index, int n_samples, tcb_error *err);
void dyno_template_fit_free(dyno_template_fit *f);

/* The pretraining loss for the target distances d [nv]; grad += its
 * gradient. */
double dyno_pretrain_loss(dyno_template_fit *f, const dyno_shape *s, const dyno_shape *grad, const float *d);

typedef struct dyno_template_terms {
    double chamfer, normal, sdf, total;
    int n_verts, n_faces; /* of the extracted template */
} dyno_template_terms;

/* Stage 1's loss with samples drawn from rng; grad += its gradient. A
 * template with no surface (the SDF of one sign everywhere) is
 * TCB_ERR_NUMERIC, where the reference exits. */
int dyno_template_loss(dyno_template_fit *f, const dyno_shape *s, const dyno_shape *grad, struct tcb_rng *rng,
                       dyno_template_terms *t, tcb_error *err);

/* The template the network makes now: the zero set of its SDF on the
 * deformed grid, normalised frame. */
int dyno_template_extract(dyno_template_fit *f, const dyno_shape *s, tcb_mt_surface *out, tcb_error *err);

/* The zero set of the pretraining's target d [nv] (the hull's signed
 * distance) on the undeformed grid: the template the pretraining tends
 * to, about the size of a fitted one, from which train_steps' calibration
 * starts stage 2 without training the shape network first. Like
 * dyno_template_extract it leaves the grid it contoured in f->v and its
 * values in f->sdf (stage 2 reads both). */
int dyno_template_extract_target(dyno_template_fit *f, const float *d, tcb_mt_surface *out, tcb_error *err);

#endif
