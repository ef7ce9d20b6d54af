/* PDG's optimisation step and its checkpoints (methods/pdg/train.h). */
#include "methods/pdg/train.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "neural/robust_chamfer.h"
#include "neural/train_ckpt.h"
#include "neural/train_loop.h"

tcb_pdg_arch tcb_pdg_arch_reference(void)
{
    return (tcb_pdg_arch){10, TCB_PDG_RELEASED, 0.25, 1.5, 16.0, 250.0, 0.3};
}

static size_t n_fields(const tcb_pdg_trainer *t) { return t->fields.off[t->fields.levels]; }

int tcb_pdg_trainer_init(tcb_pdg_trainer *t, const tcb_pdg_arch *a, const tcb_pdg_schedule *s, const tcb_pdg_data *d,
                         tcb_error *err)
{
    memset(t, 0, sizeof *t);
    if (s->epochs < 1 || s->warmup < 0 || !(s->lr_grid > 0) || !(s->lr_growth > 0) || !(s->lr_template > 0) ||
        !(s->divergence >= 0))
        return tcb_fail(err, TCB_ERR_INPUT, "pdg: invalid schedule (epochs %lld, warm-up %lld, lr %g, %g, %g)",
                        s->epochs, s->warmup, s->lr_grid, s->lr_growth, s->lr_template);
    t->arch = *a, t->sched = *s, t->data = d;
    const tcb_mesh *m = d->template_mesh;
    int rc = tcb_pdg_fields_init(&t->fields, a->levels, d->n - 1, a->rotation, a->lambda, a->lambda_growth, err);
    if (!rc) rc = tcb_large_steps_init(&t->template_ls, m->n_verts, m->faces, m->n_faces, a->template_lambda, err);
    if (rc) {
        tcb_pdg_trainer_free(t);
        return rc;
    }
    size_t nf = n_fields(t), nv3 = 3 * (size_t)m->n_verts;
    t->n_params = nf + nv3;
    t->params = calloc(t->n_params, sizeof *t->params);
    t->grads = malloc(t->n_params * sizeof *t->grads);
    t->values = malloc(nf * sizeof *t->values);
    t->verts = malloc(nv3 * sizeof *t->verts);
    t->edge_len = malloc((size_t)(t->template_ls.ne ? t->template_ls.ne : 1) * sizeof *t->edge_len);
    t->scratch = malloc(tcb_pdg_fields_scratch(&t->fields) * sizeof *t->scratch);
    rc = t->params && t->grads && t->values && t->verts && t->edge_len && t->scratch
             ? tcb_adam_init(&t->adam, t->n_params, err)
             : tcb_fail(err, TCB_ERR_NOMEM, "pdg: out of memory for %zu parameters", t->n_params);
    if (rc) {
        tcb_pdg_trainer_free(t);
        return rc;
    }
    tcb_large_steps_apply(&t->template_ls, m->verts, t->params + nf);
    for (int l = 0; l <= a->levels; l++) t->bounds[l] = t->fields.off[l];
    t->bounds[a->levels + 1] = t->n_params;
    for (int l = 0; l < a->levels; l++) t->lrs[l] = s->lr_grid * pow(s->lr_growth, l);
    t->lrs[a->levels] = s->lr_template;
    return TCB_OK;
}

void tcb_pdg_trainer_free(tcb_pdg_trainer *t)
{
    tcb_pdg_fields_free(&t->fields);
    tcb_large_steps_free(&t->template_ls);
    tcb_adam_free(&t->adam);
    free(t->params), free(t->grads), free(t->values), free(t->verts), free(t->edge_len), free(t->scratch);
    memset(t, 0, sizeof *t);
}

/* v of the parameters u, and its edge lengths. */
static int template_of_params(tcb_pdg_trainer *t, tcb_error *err)
{
    int rc = tcb_large_steps_solve(&t->template_ls, t->params + n_fields(t), t->verts, err);
    for (int e = 0; !rc && e < t->template_ls.ne; e++) {
        const float *a = t->verts + 3 * (size_t)t->template_ls.edges[2 * e],
                    *b = t->verts + 3 * (size_t)t->template_ls.edges[2 * e + 1];
        double d = 0;
        for (int k = 0; k < 3; k++) d += ((double)a[k] - b[k]) * ((double)a[k] - b[k]);
        t->edge_len[e] = (float)sqrt(d);
    }
    return rc;
}

static tcb_pdg_problem problem_of(const tcb_pdg_trainer *t)
{
    const tcb_pdg_data *d = t->data;
    return (tcb_pdg_problem){d->n,          d->key,   d->points,           d->n_points,
                             d->points_index, d->template_mesh->n_verts, t->verts, t->template_ls.ne,
                             t->template_ls.edges, t->edge_len};
}

int tcb_pdg_train_step(tcb_pdg_trainer *t, double *loss, tcb_error *err)
{
    const tcb_pdg_data *d = t->data;
    size_t nf = n_fields(t);
    int nv = d->template_mesh->n_verts;
    float *du = t->grads + nf;
    int rc = template_of_params(t, err);
    /* the template: the robust Chamfer to the keyframe's points, its
     * gradient mapped to u through the same solve */
    if (!rc)
        rc = tcb_robust_chamfer(t->verts, nv, d->points[d->key], d->n_points[d->key], d->points_index[d->key],
                                t->arch.alpha, &t->template_loss, du, err);
    if (!rc) rc = tcb_large_steps_solve(&t->template_ls, du, du, err);
    /* the fields: V = M⁻¹U, the objective's dV, dU = M⁻¹dV */
    if (!rc) {
        tcb_pdg_fields_solve(&t->fields, t->params, t->values, t->scratch);
        const tcb_pdg_problem p = problem_of(t);
        const tcb_pdg_weights w = {t->arch.edge_weight, t->arch.alpha, t->sched.warmup};
        rc = tcb_pdg_loss_grad(&t->fields, t->values, &p, &w, t->it, t->sched.epochs, &t->last, t->grads, err);
    }
    if (!rc) {
        tcb_pdg_fields_solve(&t->fields, t->grads, t->grads, t->scratch);
        *loss = t->last.total;
        rc = isfinite(*loss) ? tcb_train_guard("pdg", t->it, *loss, t->grads, t->n_params, t->sched.divergence,
                                               &t->loss0, err)
                             : tcb_fail(err, TCB_ERR_NUMERIC, "pdg: loss is %g", *loss);
    }
    if (rc) return rc;
    tcb_adam_step_groups(&t->adam, t->params, t->grads, t->bounds, t->lrs, t->arch.levels + 1);
    t->it++;
    return TCB_OK;
}

int tcb_pdg_trainer_frames(tcb_pdg_trainer *t, float *X, tcb_error *err)
{
    int rc = template_of_params(t, err);
    if (rc) return rc;
    tcb_pdg_fields_solve(&t->fields, t->params, t->values, t->scratch);
    const tcb_pdg_problem p = problem_of(t);
    return tcb_pdg_propagate(&t->fields, t->values, &p, X, err);
}

static const char *const int_names[] = {"levels", "rotation", "frames", "keyframe", "template vertices",
                                        "template faces", "epochs", "warm-up"};
static const char *const real_names[] = {"lambda", "lambda_growth", "template_lambda", "edge_weight",
                                         "alpha", "lr_grid", "lr_growth", "lr_template"};

/* The checkpoint of t (written through only by load). */
static tcb_ckpt_spec spec_of(tcb_pdg_trainer *t, uint64_t seed)
{
    const tcb_pdg_arch *a = &t->arch;
    const tcb_pdg_schedule *s = &t->sched;
    const tcb_pdg_data *d = t->data;
    return (tcb_ckpt_spec){
        .magic = "TCBPDG02", .what = "a PDG training checkpoint", /* 02: the rotation among the settings */
        .n_ints = 8, .n_reals = 8, .n_arrays = 3, .int_names = int_names, .real_names = real_names,
        .ints = {a->levels, a->rotation, d->n, d->key, d->template_mesh->n_verts, d->template_mesh->n_faces, s->epochs,
                 s->warmup},
        .reals = {a->lambda, a->lambda_growth, a->template_lambda, a->edge_weight, a->alpha, s->lr_grid, s->lr_growth,
                  s->lr_template},
        .seed = seed, .max_it = s->epochs,
        .arrays = {{t->params, t->n_params}, {t->adam.m, t->n_params}, {t->adam.v, t->n_params}},
        .state = {.it = &t->it, .rng = NULL, .adam = &t->adam, .loss0 = &t->loss0},
    };
}

int tcb_pdg_train_save(const tcb_pdg_trainer *t, uint64_t seed, double seconds, const char *path, tcb_error *err)
{
    tcb_ckpt_spec s = spec_of((tcb_pdg_trainer *)t, seed); /* read only here */
    return tcb_ckpt_spec_save(&s, seconds, path, err);
}

int tcb_pdg_train_load(tcb_pdg_trainer *t, uint64_t seed, const char *path, double *seconds, tcb_error *err)
{
    tcb_ckpt_spec s = spec_of(t, seed);
    return tcb_ckpt_spec_load(&s, path, seconds, err);
}
