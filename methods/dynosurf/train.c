/* DynoSurf's optimisation (methods/dynosurf/train.h). */
#include "methods/dynosurf/train.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "neural/train_ckpt.h"
#include "neural/train_loop.h"

const char *const dyno_phase_names[DYNO_PHASES] = {"pretrain", "template", "blend", "motion"};

long long dyno_total_steps(const dyno_schedule *s)
{
    long long n = 0;
    for (int k = 0; k < DYNO_PHASES; k++) n += s->steps[k];
    return n;
}

int dyno_phase_of(const dyno_schedule *s, long long it, long long *start)
{
    long long at = 0;
    for (int k = 0; k < DYNO_PHASES; k++) {
        if (it < at + s->steps[k] || k == DYNO_PHASES - 1) {
            *start = at;
            return k;
        }
        at += s->steps[k];
    }
    return DYNO_PHASES - 1; /* not reached */
}

int dyno_trainer_init(dyno_trainer *t, const dyno_problem *p, const dyno_schedule *s, uint64_t seed, tcb_error *err)
{
    memset(t, 0, sizeof *t);
    for (int k = 0; k < DYNO_PHASES; k++)
        if (s->steps[k] < 0) return tcb_fail(err, TCB_ERR_INPUT, "dynosurf: %lld %s steps", s->steps[k], dyno_phase_names[k]);
    if (s->samples < 1 || s->grid_samples < 1 || s->blend_points < 1 || !(s->lr > 0) || !(s->divergence >= 0))
        return tcb_fail(err, TCB_ERR_INPUT, "dynosurf: invalid schedule (samples %d, grid samples %d, lr %g)",
                        s->samples, s->grid_samples, s->lr);
    t->p = p, t->s = *s;
    t->n_shape = dyno_shape_size();
    t->n_params = t->n_shape + dyno_deformer_size();
    t->params = malloc(t->n_params * sizeof *t->params);
    t->grads = malloc(t->n_params * sizeof *t->grads);
    t->blend_pts = malloc((size_t)s->blend_points * 3 * sizeof *t->blend_pts);
    int rc = t->params && t->grads && t->blend_pts
                 ? tcb_adam_init(&t->adam, t->n_params, err)
                 : tcb_fail(err, TCB_ERR_NOMEM, "dynosurf: out of memory for %zu parameters", t->n_params);
    if (!rc)
        rc = dyno_template_fit_init(&t->tfit, p->grid, p->edge, p->pts[p->key], p->normals[p->key], p->n_pts[p->key],
                                    p->index[p->key], s->samples, err);
    if (!rc) rc = dyno_blend_alloc(&t->bpre, s->blend_points, err);
    if (!rc) {
        dyno_shape_bind(&t->shape, t->params), dyno_shape_bind(&t->gshape, t->grads);
        dyno_deformer_bind(&t->def, t->params + t->n_shape), dyno_deformer_bind(&t->gdef, t->grads + t->n_shape);
        tcb_rng_seed_stream(&t->rng, seed, "dynosurf");
        dyno_shape_init(&t->shape, &t->rng);
        rc = dyno_deformer_init(&t->def, p->grid->verts, p->grid->n_verts, &t->rng, err);
    }
    if (rc) dyno_trainer_free(t);
    return rc;
}

static void release_motion(dyno_trainer *t)
{
    if (t->motion_ready) dyno_motion_fit_free(&t->mfit);
    tcb_mt_surface_free(&t->templ);
    free(t->grid_v), free(t->grid_sdf);
    t->grid_v = t->grid_sdf = NULL;
    t->motion_ready = 0;
}

void dyno_trainer_free(dyno_trainer *t)
{
    release_motion(t);
    dyno_template_fit_free(&t->tfit);
    dyno_blend_free(&t->bpre);
    tcb_adam_free(&t->adam);
    free(t->params), free(t->grads), free(t->blend_pts);
    memset(t, 0, sizeof *t);
}

/* Stage 2's inputs from the frozen shape network: the template, the
 * deformed grid and its SDF. */
static int prepare_motion(dyno_trainer *t, tcb_error *err)
{
    if (t->motion_ready) return TCB_OK;
    const dyno_problem *p = t->p;
    size_t nv = (size_t)p->grid->n_verts;
    int rc = t->template_from_target ? dyno_template_extract_target(&t->tfit, p->hull_sd, &t->templ, err)
                                     : dyno_template_extract(&t->tfit, &t->shape, &t->templ, err);
    if (!rc && t->templ.n_faces == 0)
        rc = tcb_fail(err, TCB_ERR_NUMERIC, "dynosurf: the template after stage 1 is empty (its SDF has one sign)");
    if (!rc && (!(t->grid_v = malloc(nv * 3 * sizeof(float))) || !(t->grid_sdf = malloc(nv * sizeof(float)))))
        rc = tcb_fail(err, TCB_ERR_NOMEM, "dynosurf: out of memory for the grid");
    if (!rc) {
        memcpy(t->grid_v, t->tfit.v, nv * 3 * sizeof(float));
        memcpy(t->grid_sdf, t->tfit.sdf, nv * sizeof(float));
        dyno_motion_data d = {.n_frames = p->T, .key = p->key, .pts = p->pts, .normals = p->normals,
                              .n_pts = p->n_pts, .index = p->index, .template_verts = t->templ.verts,
                              .n_template = t->templ.n_verts, .faces = t->templ.faces, .n_faces = t->templ.n_faces,
                              .grid_v = t->grid_v, .grid_sdf = t->grid_sdf, .n_grid = (int)nv,
                              .n_samples = t->s.samples, .n_grid_samples = t->s.grid_samples,
                              .weights = DYNO_MOTION_WEIGHTS};
        rc = dyno_motion_fit_init(&t->mfit, &d, err);
    }
    if (rc) {
        release_motion(t);
        return rc;
    }
    t->motion_ready = 1;
    return TCB_OK;
}

/* The loss of the phase's objective and its gradient in t->grads. */
static int phase_loss(dyno_trainer *t, int phase, double *loss, tcb_error *err)
{
    memset(t->grads, 0, t->n_params * sizeof *t->grads);
    switch (phase) {
    case DYNO_PHASE_PRETRAIN:
        *loss = dyno_pretrain_loss(&t->tfit, &t->shape, &t->gshape, t->p->hull_sd);
        return TCB_OK;
    case DYNO_PHASE_TEMPLATE: {
        dyno_template_terms terms;
        int rc = dyno_template_loss(&t->tfit, &t->shape, &t->gshape, &t->rng, &terms, err);
        *loss = terms.total;
        return rc;
    }
    case DYNO_PHASE_BLEND:
        for (int i = 0; i < 3 * t->s.blend_points; i++) t->blend_pts[i] = (float)(tcb_rng_uniform(&t->rng) - 0.5);
        *loss = dyno_blend_pretrain_loss(&t->def, &t->gdef, &t->bpre, t->blend_pts, t->s.blend_points);
        return TCB_OK;
    default: {
        dyno_motion_terms terms;
        int rc = prepare_motion(t, err);
        if (!rc) rc = dyno_motion_loss(&t->mfit, &t->def, &t->gdef, &t->rng, &terms, err);
        *loss = terms.total;
        return rc;
    }
    }
}

void dyno_trainer_main_phase(dyno_trainer *t)
{
    release_motion(t);
    t->template_from_target = 1;
    t->it = t->s.steps[DYNO_PHASE_PRETRAIN] + t->s.steps[DYNO_PHASE_TEMPLATE] + t->s.steps[DYNO_PHASE_BLEND];
}

int dyno_train_step(dyno_trainer *t, double *loss, tcb_error *err)
{
    long long start;
    int phase = dyno_phase_of(&t->s, t->it, &start);
    if (t->it == start) tcb_adam_reset(&t->adam); /* each phase its own optimiser */
    int rc = phase_loss(t, phase, loss, err);
    if (!rc && !isfinite(*loss)) rc = tcb_fail(err, TCB_ERR_NUMERIC, "dynosurf: %s loss is %g", dyno_phase_names[phase], *loss);
    if (!rc) rc = tcb_train_guard("dynosurf", t->it - start, *loss, t->grads, t->n_params, t->s.divergence, &t->loss0, err);
    if (rc) return rc;
    /* Adam over the phase's parameters: the shape network (phases 0, 1),
     * MLP_W (2), the deformer (3); the others keep lr 0 and zero gradients. */
    size_t blend = t->n_shape + dyno_deformer_blend_offset();
    const size_t bounds[4] = {0, t->n_shape, blend, t->n_params};
    double lrs[3] = {0, 0, 0};
    if (phase <= DYNO_PHASE_TEMPLATE) lrs[0] = t->s.lr;
    else if (phase == DYNO_PHASE_BLEND) lrs[2] = t->s.lr;
    else lrs[1] = lrs[2] = t->s.lr;
    if (phase == DYNO_PHASE_BLEND) /* the pretraining moves MLP_W alone */
        memset(t->grads + t->n_shape, 0, (blend - t->n_shape) * sizeof *t->grads);
    tcb_adam_step_groups(&t->adam, t->params, t->grads, bounds, lrs, 3);
    t->last[phase] = *loss;
    t->it++;
    return TCB_OK;
}

/* The rate of the pretraining that readies stage 1's unit: at the
 * reference's 1e-4 the SDF takes 200 steps to cross zero at `cpu`'s grid,
 * at 1e-2 about 40 (measured on the calibration sequence). */
#define UNIT_PRETRAIN_LR 1e-2

static long long phase_start(const dyno_schedule *s, int phase)
{
    long long at = 0;
    for (int k = 0; k < phase; k++) at += s->steps[k];
    return at;
}

/* The faces of the shape network's zero set now. */
static int network_faces(dyno_trainer *t, int *faces, tcb_error *err)
{
    tcb_mt_surface now = {0};
    int rc = dyno_template_extract(&t->tfit, &t->shape, &now, err);
    *faces = now.n_faces;
    tcb_mt_surface_free(&now);
    return rc;
}

/* Stage 1's steps cost what a fit's do once the network's zero set is a
 * surface of a fit's size: a network short of 90 % of the faces of the
 * hull's zero set (the pretraining's target) is pretrained first, at
 * UNIT_PRETRAIN_LR, ten steps at a time, for at most the pretraining's
 * steps. */
static int ready_stage1(dyno_trainer *t, tcb_error *err)
{
    tcb_mt_surface target = {0};
    int rc = dyno_template_extract_target(&t->tfit, t->p->hull_sd, &target, err), faces = 0;
    int want = (int)(0.9 * target.n_faces);
    tcb_mt_surface_free(&target);
    if (!rc) rc = network_faces(t, &faces, err);
    double lr = t->s.lr;
    t->s.lr = UNIT_PRETRAIN_LR;
    t->it = 0;
    for (long long k = 0; !rc && faces < want && k < t->s.steps[DYNO_PHASE_PRETRAIN]; k++) {
        double loss;
        rc = dyno_train_step(t, &loss, err);
        if (!rc && (k + 1) % 10 == 0) rc = network_faces(t, &faces, err);
    }
    t->s.lr = lr;
    if (!rc && faces < want)
        rc = tcb_fail(err, TCB_ERR_NUMERIC, "dynosurf: %lld pretraining steps at %g left the template %d faces, "
                      "short of the hull's %d", t->s.steps[DYNO_PHASE_PRETRAIN], UNIT_PRETRAIN_LR, faces, want);
    return rc;
}

int dyno_trainer_unit_step(dyno_trainer *t, int phase, tcb_error *err)
{
    if (phase < 0 || phase >= DYNO_PHASE_MOTION || t->s.steps[phase] < 1)
        return tcb_fail(err, TCB_ERR_INTERNAL, "dynosurf: no unit of phase %d", phase);
    long long start = phase_start(&t->s, phase), at;
    int rc = TCB_OK;
    if (dyno_phase_of(&t->s, t->it, &at) != phase) {
        if (phase == DYNO_PHASE_TEMPLATE) rc = ready_stage1(t, err);
        t->it = start;
    }
    double loss;
    if (!rc) rc = dyno_train_step(t, &loss, err);
    if (!rc && t->it == start + t->s.steps[phase]) t->it = start; /* the next starts it over */
    return rc;
}

int dyno_trainer_frame_unit(dyno_trainer *t, tcb_error *err)
{
    int rc = TCB_OK;
    if (!t->motion_ready) {
        double loss;
        dyno_trainer_main_phase(t);
        rc = dyno_train_step(t, &loss, err);
    }
    return rc ? rc : dyno_motion_frame_cost(&t->mfit, &t->rng, 0, err);
}

int dyno_trainer_template(dyno_trainer *t, const tcb_mt_surface **out, tcb_error *err)
{
    int rc = prepare_motion(t, err);
    *out = rc ? NULL : &t->templ;
    return rc;
}

int dyno_trainer_frames(dyno_trainer *t, float *X, tcb_error *err)
{
    int rc = prepare_motion(t, err);
    if (!rc) dyno_motion_frames(&t->mfit, &t->def, X);
    return rc;
}

static const char *const int_names[] = {"pretrain steps", "template steps", "blend steps", "motion steps",
                                        "samples", "grid samples", "blend points", "frames", "keyframe",
                                        "grid vertices", "grid tets"};
static const char *const real_names[] = {"lr", "edge"};

static tcb_ckpt_spec spec_of(dyno_trainer *t, uint64_t seed)
{
    const dyno_schedule *s = &t->s;
    size_t n = t->n_params;
    return (tcb_ckpt_spec){
        .magic = "TCBDYNO1", .what = "a DynoSurf training checkpoint",
        .n_ints = 11, .n_reals = 2, .n_arrays = 3, .int_names = int_names, .real_names = real_names,
        .ints = {s->steps[0], s->steps[1], s->steps[2], s->steps[3], s->samples, s->grid_samples, s->blend_points,
                 t->p->T, t->p->key, t->p->grid->n_verts, t->p->grid->n_tets},
        .reals = {s->lr, t->p->edge},
        .seed = seed, .max_it = dyno_total_steps(s),
        .arrays = {{t->params, n}, {t->adam.m, n}, {t->adam.v, n}},
        .state = {.it = &t->it, .rng = &t->rng, .adam = &t->adam, .loss0 = &t->loss0},
    };
}

int dyno_train_save(const dyno_trainer *t, uint64_t seed, double seconds, const char *path, tcb_error *err)
{
    tcb_ckpt_spec s = spec_of((dyno_trainer *)t, seed); /* read only here */
    return tcb_ckpt_spec_save(&s, seconds, path, err);
}

int dyno_train_load(dyno_trainer *t, uint64_t seed, const char *path, double *seconds, tcb_error *err)
{
    tcb_ckpt_spec s = spec_of(t, seed);
    int rc = tcb_ckpt_spec_load(&s, path, seconds, err);
    if (!rc) release_motion(t), t->template_from_target = 0; /* the template follows the loaded weights */
    return rc;
}
