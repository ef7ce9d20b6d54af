/* DynoSurf's template objectives (methods/dynosurf/template.h). */
#include "methods/dynosurf/template.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "neural/approx_sdf.h"
#include "neural/chamfer_l1.h"

int dyno_template_fit_init(dyno_template_fit *f, const tcb_tetmesh *grid, float edge, const float *pts,
                           const float *normals, int n_pts, const tcb_nn *index, int n_samples, tcb_error *err)
{
    *f = (dyno_template_fit){.grid = grid, .edge = edge, .pts = pts, .normals = normals, .n_pts = n_pts,
                             .index = index, .n_samples = n_samples,
                             .weights = DYNO_TEMPLATE_WEIGHTS};
    if (n_pts < TCB_APPROX_SDF_K)
        return tcb_fail(err, TCB_ERR_INPUT, "dynosurf: the keyframe has %d points, need at least %d", n_pts,
                        TCB_APPROX_SDF_K);
    if (n_samples < 1) return tcb_fail(err, TCB_ERR_INPUT, "dynosurf: %d surface samples", n_samples);
    int rc = dyno_shape_acts_alloc(&f->acts, grid->n_verts, err);
    if (rc) return rc;
    size_t nv = (size_t)grid->n_verts, m = (size_t)n_samples;
    f->sdf = malloc(nv * sizeof(float)), f->v = malloc(nv * 3 * sizeof(float));
    f->dsdf = malloc(nv * sizeof(float)), f->dv = malloc(nv * 3 * sizeof(float));
    f->dout = malloc(nv * DYNO_SHAPE_OUT * sizeof(float));
    f->s = malloc(nv * sizeof(float)), f->ds = malloc(nv * sizeof(float));
    f->nbr = malloc(nv * TCB_APPROX_SDF_K * sizeof(int32_t));
    f->draws = malloc(m * sizeof *f->draws);
    f->x = malloc(m * 3 * sizeof(float)), f->nx = malloc(m * 3 * sizeof(float));
    f->dx = malloc(m * 3 * sizeof(float)), f->dnx = malloc(m * 3 * sizeof(float));
    if (f->sdf && f->v && f->dsdf && f->dv && f->dout && f->s && f->ds && f->nbr && f->draws && f->x &&
        f->nx && f->dx && f->dnx)
        return TCB_OK;
    dyno_template_fit_free(f);
    return tcb_fail(err, TCB_ERR_NOMEM, "dynosurf: out of memory for a template of %d vertices", grid->n_verts);
}

void dyno_template_fit_free(dyno_template_fit *f)
{
    dyno_shape_acts_free(&f->acts);
    free(f->sdf), free(f->v), free(f->dsdf), free(f->dv), free(f->dout);
    free(f->s), free(f->ds), free(f->nbr), free(f->draws);
    free(f->x), free(f->nx), free(f->dx), free(f->dnx);
    memset(f, 0, sizeof *f);
}

/* The network at the grid's vertices: f->sdf and the deformed f->v. */
static void evaluate(dyno_template_fit *f, const dyno_shape *s)
{
    dyno_shape_forward(s, &f->acts, f->grid->verts);
    dyno_shape_readout(f->acts.out, f->grid->verts, f->grid->n_verts, f->edge, f->sdf, f->v);
}

double dyno_pretrain_loss(dyno_template_fit *f, const dyno_shape *s, const dyno_shape *grad, const float *d)
{
    evaluate(f, s);
    int nv = f->grid->n_verts;
    double loss = 0;
    for (int i = 0; i < nv; i++) {
        double r = (double)f->sdf[i] - d[i];
        loss += r * r / nv;
        f->dsdf[i] = (float)(2 * r / nv);
    }
    dyno_shape_readout_backward(f->acts.out, nv, f->edge, f->dsdf, NULL, f->dout);
    dyno_shape_backward(s, grad, &f->acts, f->dout);
    return loss;
}

int dyno_template_extract(dyno_template_fit *f, const dyno_shape *s, tcb_mt_surface *out, tcb_error *err)
{
    evaluate(f, s);
    return tcb_marching_tets_forward(f->v, f->sdf, f->grid->n_verts, f->grid->tets, f->grid->n_tets, out, err);
}

int dyno_template_extract_target(dyno_template_fit *f, const float *d, tcb_mt_surface *out, tcb_error *err)
{
    size_t nv = (size_t)f->grid->n_verts;
    memcpy(f->v, f->grid->verts, nv * 3 * sizeof *f->v);
    memcpy(f->sdf, d, nv * sizeof *f->sdf);
    return tcb_marching_tets_forward(f->v, f->sdf, f->grid->n_verts, f->grid->tets, f->grid->n_tets, out, err);
}

static double sgn(double v) { return (v > 0) - (v < 0); }

/* The L1 term 50 · mean |sdf − s(v)|: its value, ∂/∂sdf into f->dsdf and
 * ∂/∂v (through s) into f->dv, both overwritten. */
static int sdf_term(dyno_template_fit *f, double *value, tcb_error *err)
{
    int nv = f->grid->n_verts;
    int rc = tcb_approx_sdf_forward(f->s, f->nbr, f->v, nv, f->index, f->pts, f->normals, TCB_APPROX_SDF_K,
                                    TCB_APPROX_SDF_RADIUS, err);
    if (rc) return rc;
    double sum = 0, scale = f->weights.sdf / nv;
    for (int i = 0; i < nv; i++) {
        double r = (double)f->sdf[i] - f->s[i];
        sum += fabs(r);
        f->dsdf[i] = (float)(scale * sgn(r));
        f->ds[i] = -f->dsdf[i];
    }
    *value = sum / nv;
    tcb_approx_sdf_backward(f->dv, f->ds, f->v, nv, f->nbr, f->pts, f->normals, TCB_APPROX_SDF_K,
                            TCB_APPROX_SDF_RADIUS);
    return TCB_OK;
}

/* The Chamfer and normal terms on samples of the surface; their gradient
 * through the samples, the surface and marching tetrahedra is added to
 * f->dv and f->dsdf. */
static int surface_terms(dyno_template_fit *f, const tcb_mt_surface *surf, struct tcb_rng *rng,
                         dyno_template_terms *t, tcb_error *err)
{
    int m = f->n_samples;
    int rc = tcb_mesh_sample_draw(surf->verts, surf->faces, surf->n_faces, m, rng, f->draws, err);
    if (rc) return rc;
    tcb_mesh_sample_forward(surf->verts, surf->faces, f->draws, m, f->x, f->nx);
    rc = tcb_chamfer_l1(f->x, f->nx, m, f->pts, f->normals, f->n_pts, f->index, &t->chamfer, &t->normal, f->dx,
                        f->dnx, err);
    if (rc) return rc;
    for (size_t i = 0; i < 3 * (size_t)m; i++)
        f->dx[i] *= (float)f->weights.chamfer, f->dnx[i] *= (float)f->weights.normal;
    float *dverts = calloc((size_t)surf->n_verts * 3, sizeof *dverts);
    float *face_grad = malloc((size_t)surf->n_faces * 3 * sizeof *face_grad);
    if (!dverts || !face_grad) {
        free(dverts), free(face_grad);
        return tcb_fail(err, TCB_ERR_NOMEM, "dynosurf: out of memory for a template of %d faces", surf->n_faces);
    }
    tcb_mesh_sample_backward(surf->verts, surf->faces, surf->n_faces, f->draws, m, f->dx, f->dnx, face_grad, dverts);
    tcb_marching_tets_backward(f->v, f->sdf, surf, dverts, f->dv, f->dsdf);
    free(dverts), free(face_grad);
    return TCB_OK;
}

int dyno_template_loss(dyno_template_fit *f, const dyno_shape *s, const dyno_shape *grad, struct tcb_rng *rng,
                       dyno_template_terms *t, tcb_error *err)
{
    memset(t, 0, sizeof *t);
    evaluate(f, s);
    tcb_mt_surface surf;
    int rc = tcb_marching_tets_forward(f->v, f->sdf, f->grid->n_verts, f->grid->tets, f->grid->n_tets, &surf, err);
    if (rc) return rc;
    t->n_verts = surf.n_verts, t->n_faces = surf.n_faces;
    if (surf.n_faces == 0) {
        tcb_mt_surface_free(&surf);
        return tcb_fail(err, TCB_ERR_NUMERIC, "dynosurf: the template's SDF does not cross zero on the grid");
    }
    rc = sdf_term(f, &t->sdf, err);
    if (!rc) rc = surface_terms(f, &surf, rng, t, err);
    tcb_mt_surface_free(&surf);
    if (rc) return rc;
    t->total = f->weights.chamfer * t->chamfer + f->weights.normal * t->normal + f->weights.sdf * t->sdf;
    dyno_shape_readout_backward(f->acts.out, f->grid->n_verts, f->edge, f->dsdf, f->dv, f->dout);
    dyno_shape_backward(s, grad, &f->acts, f->dout);
    return TCB_OK;
}
