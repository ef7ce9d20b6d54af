/* DynoSurf's optimisation, its four phases in one count of iterations
 * (github yaoyx689/DynoSurf @ a2b7324: code/trainer.py __init__ L22-71,
 * train_template L141-157, train_joint L162-181; code/model/
 * deformer_network.py pre_train_vn_weights L130-155; confs/base.conf):
 *
 *   phase      iterations  updates (Adam, lr 1e-4, fresh each phase)
 *   pretrain   1 000       the shape network, to the hull's signed distance
 *   template   5 000       the shape network, stage 1 on the keyframe
 *   blend      4 000       MLP_W, to the Gaussian weights at 1 024 points
 *                          drawn U[−½, ½]³ each step
 *   motion     10 000      the control points, MLP_T and MLP_W: stage 2
 *                          over every frame, the template frozen
 *
 * Every draw (the control points' start, surface samples, grid picks,
 * blend points) comes from one seeded stream, so a run is reproducible and
 * a checkpoint continues it bit for bit. The template is extracted when
 * stage 2 first needs it (after stage 1, or on resuming past it). */
#ifndef TCB_DYNOSURF_TRAIN_H
#define TCB_DYNOSURF_TRAIN_H

#include <stdint.h>

#include "methods/dynosurf/deformer.h"
#include "methods/dynosurf/motion.h"
#include "methods/dynosurf/shape.h"
#include "methods/dynosurf/template.h"
#include "neural/adam.h"
#include "tcb/rng.h"

enum { DYNO_PHASE_PRETRAIN, DYNO_PHASE_TEMPLATE, DYNO_PHASE_BLEND, DYNO_PHASE_MOTION, DYNO_PHASES };
extern const char *const dyno_phase_names[DYNO_PHASES];

typedef struct dyno_schedule {
    long long steps[DYNO_PHASES]; /* 1 000, 5 000, 4 000, 10 000 */
    int samples;                  /* surface samples a frame: 10 000 */
    int grid_samples;             /* grid vertices stage 2 picks: 10 000 */
    int blend_points;             /* 1 024 */
    double lr;                    /* 1e-4 */
    double divergence;            /* 0: no test; else per phase against its first loss */
} dyno_schedule;

#define DYNO_SCHEDULE_PAPER ((dyno_schedule){{1000, 5000, 4000, 10000}, 10000, 10000, 1024, 1e-4, 0})

/* The inputs, the caller's for the trainer's life: every frame's points
 * and normals in DynoSurf's frame, indexed; the keyframe; the grid, its
 * edge bound and the hull's signed distance at its vertices. */
typedef struct dyno_problem {
    int T, key;
    const float *const *pts, *const *normals;
    const int *n_pts;
    const tcb_nn *const *index;
    const tcb_tetmesh *grid;
    float edge;
    const float *hull_sd;
} dyno_problem;

typedef struct dyno_trainer {
    const dyno_problem *p;
    dyno_schedule s;
    size_t n_shape, n_params;   /* the shape network's, then the deformer's */
    float *params, *grads;
    dyno_shape shape, gshape;
    dyno_deformer def, gdef;
    tcb_adam adam;
    long long it;               /* iterations done, over all phases */
    double loss0;               /* the current phase's first loss */
    tcb_rng rng;
    dyno_template_fit tfit;
    dyno_blend bpre;
    float *blend_pts;           /* [blend_points][3] */
    /* Stage 2's template, extracted from the frozen shape network (or,
     * after dyno_trainer_main_phase, from the pretraining's target). */
    int motion_ready, template_from_target;
    tcb_mt_surface templ;
    float *grid_v, *grid_sdf;   /* the deformed grid and its SDF */
    dyno_motion_fit mfit;
    double last[DYNO_PHASES];   /* each phase's last loss */
} dyno_trainer;

/* Both networks initialised from seed (PyTorch's Linear initialisation)
 * and the control points by farthest points of the grid. */
int dyno_trainer_init(dyno_trainer *t, const dyno_problem *p, const dyno_schedule *s, uint64_t seed, tcb_error *err);
void dyno_trainer_free(dyno_trainer *t);

long long dyno_total_steps(const dyno_schedule *s);
/* The phase of iteration it and the iteration it starts at. */
int dyno_phase_of(const dyno_schedule *s, long long it, long long *start);

/* train_steps' calibration (tcbench calibrate, bench_train_step): a fresh
 * trainer moved to stage 2's first step, the phase that dominates a fit
 * (docs/protocol.md, "DynoSurf": about half of a `cpu` fit's time, and
 * the phase that grows with the frames). Its template is the zero set of
 * the hull's signed distance, the pretraining's target, instead of stage
 * 1's; the deformer as initialised. A step then costs what a fit's
 * stage-2 step costs on a template of that size. */
void dyno_trainer_main_phase(dyno_trainer *t);

/* tcbench calibrate's units: one step of `phase` (pretrain, template or
 * blend; stage 2 is train_steps'), the trainer moved to the phase's start
 * when not in it and back there at its end. Stage 1's needs a network
 * whose zero set is a surface: a trainer without one is pretrained first
 * (at a larger rate than the reference's, to reach it in fewer steps). */
int dyno_trainer_unit_step(dyno_trainer *t, int phase, tcb_error *err);

/* tcbench calibrate's `frame` unit: what one frame adds to a stage-2
 * step (dyno_motion_frame_cost, frame 0), after a stage-2 step from
 * dyno_trainer_main_phase when the trainer has taken none. */
int dyno_trainer_frame_unit(dyno_trainer *t, tcb_error *err);

/* One iteration of whichever phase it is in. */
int dyno_train_step(dyno_trainer *t, double *loss, tcb_error *err);

/* The template (after stage 1): its vertices and faces. */
int dyno_trainer_template(dyno_trainer *t, const tcb_mt_surface **out, tcb_error *err);

/* X [T][template vertices][3]: the template carried into every frame. */
int dyno_trainer_frames(dyno_trainer *t, float *X, tcb_error *err);

/* The whole training state; a checkpoint of other settings is refused. */
int dyno_train_save(const dyno_trainer *t, uint64_t seed, double seconds, const char *path, tcb_error *err);
int dyno_train_load(dyno_trainer *t, uint64_t seed, const char *path, double *seconds, tcb_error *err);

#endif
