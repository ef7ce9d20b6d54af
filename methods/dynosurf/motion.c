/* DynoSurf's stage 2 (methods/dynosurf/motion.h). */
#include "methods/dynosurf/motion.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "neural/approx_sdf.h"
#include "neural/robust_chamfer.h"
#include "tcb/rng.h"

enum { K = DYNO_CONTROL_POINTS };

int dyno_motion_fit_init(dyno_motion_fit *f, const dyno_motion_data *data, tcb_error *err)
{
    memset(f, 0, sizeof *f);
    f->data = *data;
    dyno_motion_data *d = &f->data;
    if (d->n_grid_samples > d->n_grid) d->n_grid_samples = d->n_grid;
    for (int t = 0; t < d->n_frames; t++)
        if (d->n_pts[t] < TCB_APPROX_SDF_K)
            return tcb_fail(err, TCB_ERR_INPUT, "dynosurf: frame %d has %d points, need at least %d", t, d->n_pts[t],
                            TCB_APPROX_SDF_K);
    size_t F = (size_t)d->n_frames, m = (size_t)d->n_template, g = (size_t)d->n_grid_samples,
           ms = (size_t)d->n_samples;
    f->frames = malloc(F * sizeof *f->frames), f->perm = malloc((size_t)d->n_grid * sizeof *f->perm);
    f->X = malloc(F * m * 3 * sizeof(float)), f->dX = malloc(F * m * 3 * sizeof(float));
    f->y = malloc(g * 3 * sizeof(float)), f->yhat = malloc(g * sizeof(float));
    f->Y = malloc(F * g * 3 * sizeof(float)), f->dY = malloc(F * g * 3 * sizeof(float));
    f->s = malloc(F * g * sizeof(float)), f->ds = malloc(F * g * sizeof(float));
    f->nbr = malloc(F * g * TCB_APPROX_SDF_K * sizeof(int32_t));
    f->draws = malloc(F * ms * sizeof *f->draws);
    size_t th = (size_t)(f->n_scratch = omp_get_max_threads());
    f->xs = malloc(th * ms * 3 * sizeof(float)), f->nxs = malloc(th * ms * 3 * sizeof(float));
    f->dxs = malloc(th * ms * 3 * sizeof(float)), f->dnxs = malloc(th * ms * 3 * sizeof(float));
    f->face_grad = malloc(th * (size_t)d->n_faces * 3 * sizeof(float));
    f->frame_cd = malloc(F * sizeof(double)), f->frame_normal = malloc(F * sizeof(double));
    int ok = f->frames && f->perm && f->X && f->dX && f->y && f->yhat && f->Y && f->dY && f->s && f->ds && f->nbr &&
             f->draws && f->xs && f->nxs && f->dxs && f->dnxs && f->face_grad && f->frame_cd && f->frame_normal;
    int rc = ok ? dyno_blend_alloc(&f->bt, d->n_template, err)
                : tcb_fail(err, TCB_ERR_NOMEM, "dynosurf: out of memory for stage 2 over %d frames", d->n_frames);
    if (!rc) rc = dyno_blend_alloc(&f->bg, d->n_grid_samples, err);
    if (!rc) rc = dyno_transforms_alloc(&f->tr, d->n_frames, err);
    if (rc) {
        dyno_motion_fit_free(f);
        return rc;
    }
    for (int t = 0; t < d->n_frames; t++) f->frames[t] = t;
    return TCB_OK;
}

void dyno_motion_fit_free(dyno_motion_fit *f)
{
    dyno_blend_free(&f->bt), dyno_blend_free(&f->bg), dyno_transforms_free(&f->tr);
    free(f->frames), free(f->perm), free(f->X), free(f->dX), free(f->y), free(f->yhat), free(f->Y), free(f->dY);
    free(f->s), free(f->ds), free(f->nbr), free(f->draws), free(f->xs), free(f->nxs), free(f->dxs), free(f->dnxs);
    free(f->face_grad), free(f->frame_cd), free(f->frame_normal);
    memset(f, 0, sizeof *f);
}

/* g grid vertices without replacement (a partial Fisher–Yates shuffle of
 * the identity, so that the picks depend on the stream alone and a resumed
 * run draws what the unbroken one drew), their positions and SDF values. */
static void pick_grid(dyno_motion_fit *f, struct tcb_rng *rng)
{
    const dyno_motion_data *d = &f->data;
    for (int i = 0; i < d->n_grid; i++) f->perm[i] = i;
    for (int i = 0; i < d->n_grid_samples; i++) {
        int j = i + (int)tcb_rng_below(rng, (uint32_t)(d->n_grid - i));
        int32_t keep = f->perm[i];
        f->perm[i] = f->perm[j], f->perm[j] = keep;
        memcpy(f->y + 3 * (size_t)i, d->grid_v + 3 * (size_t)f->perm[i], 3 * sizeof(float));
        f->yhat[i] = d->grid_sdf[f->perm[i]];
    }
}

/* X_t and Y_t from the blend weights and frame t's transforms. */
static void deform_frame(dyno_motion_fit *f, int t)
{
    const dyno_motion_data *d = &f->data;
    size_t m = (size_t)d->n_template, g = (size_t)d->n_grid_samples;
    const float *R = f->tr.R + 9 * K * t, *raw = f->tr.raw + 6 * K * t;
    dyno_deform_apply(d->template_verts, d->n_template, f->bt.w, R, raw, f->X + 3 * m * t);
    dyno_deform_apply(f->y, d->n_grid_samples, f->bg.w, R, raw, f->Y + 3 * g * t);
}

/* dX_t and dY_t back through frame t's deformation: into its transforms'
 * gradient and, added, the blend weights'. */
static void deform_frame_backward(dyno_motion_fit *f, int t)
{
    const dyno_motion_data *d = &f->data;
    size_t m = (size_t)d->n_template, g = (size_t)d->n_grid_samples;
    const float *R = f->tr.R + 9 * K * t, *raw = f->tr.raw + 6 * K * t;
    float *dR = f->tr.dR + 9 * K * t, *draw = f->tr.draw + 6 * K * t;
    dyno_deform_apply_backward(d->template_verts, d->n_template, f->bt.w, R, raw, f->dX + 3 * m * t, dR, draw,
                               f->bt.dw);
    dyno_deform_apply_backward(f->y, d->n_grid_samples, f->bg.w, R, raw, f->dY + 3 * g * t, dR, draw, f->bg.dw);
}

/* X and Y of every frame from the current deformer. */
static void deform_all(dyno_motion_fit *f, const dyno_deformer *dfm)
{
    const dyno_motion_data *d = &f->data;
    dyno_blend_forward(dfm, &f->bt, d->template_verts, d->n_template);
    dyno_blend_forward(dfm, &f->bg, f->y, d->n_grid_samples);
    dyno_transforms_forward(dfm, &f->tr, f->frames, d->n_frames);
#pragma omp parallel for schedule(static)
    for (int t = 0; t < d->n_frames; t++) deform_frame(f, t);
}

/* Frame u's robust Chamfer and normal terms from its drawn samples, their
 * gradient (weighted by wc, wn) into f->dX, with thread th's scratch. */
static int chamfer_frame(dyno_motion_fit *f, int u, int th, float wc, float wn, tcb_error *err)
{
    const dyno_motion_data *d = &f->data;
    size_t m = (size_t)d->n_template, ms = (size_t)d->n_samples, at = (size_t)th * ms * 3;
    const float *X = f->X + 3 * m * u;
    const tcb_mesh_draw *draws = f->draws + ms * u;
    float *xs = f->xs + at, *nxs = f->nxs + at, *dxs = f->dxs + at, *dnxs = f->dnxs + at;
    tcb_mesh_sample_forward(X, d->faces, draws, (int)ms, xs, nxs);
    int rc = tcb_robust_chamfer_normals(xs, nxs, (int)ms, d->pts[u], d->normals[u], d->n_pts[u], d->index[u],
                                        TCB_ROBUST_CHAMFER_ALPHA, &f->frame_cd[u], &f->frame_normal[u], dxs, dnxs,
                                        err);
    if (rc) return rc;
    for (size_t i = 0; i < 3 * ms; i++) dxs[i] *= wc, dnxs[i] *= wn;
    tcb_mesh_sample_backward(X, d->faces, d->n_faces, draws, (int)ms, dxs, dnxs,
                             f->face_grad + (size_t)th * d->n_faces * 3, f->dX + 3 * m * u);
    return TCB_OK;
}

/* The robust Chamfer and normal terms, means over frames; their gradient
 * (weighted) into f->dX through the samples. Every frame's samples are
 * drawn first, in frame order from the one stream; the frames then go
 * side by side, and their terms are summed in frame order, so the result
 * does not depend on the threads. */
static int chamfer_terms(dyno_motion_fit *f, struct tcb_rng *rng, dyno_motion_terms *t, tcb_error *err)
{
    const dyno_motion_data *d = &f->data;
    size_t m = (size_t)d->n_template;
    int ms = d->n_samples, F = d->n_frames, failed = 0;
    float wc = (float)(d->weights.chamfer / F), wn = (float)(d->weights.normal / F);
    for (int u = 0; u < F; u++) {
        int rc = tcb_mesh_sample_draw(f->X + 3 * m * u, d->faces, d->n_faces, ms, rng, f->draws + (size_t)ms * u, err);
        if (rc) return rc;
    }
#pragma omp parallel for schedule(dynamic) num_threads(f->n_scratch)
    for (int u = 0; u < F; u++) {
        tcb_error mine = {0};
        int rc = chamfer_frame(f, u, omp_get_thread_num(), wc, wn, &mine);
        if (rc) {
#pragma omp critical(dyno_chamfer_failure)
            if (!failed) failed = rc, *err = mine;
        }
    }
    if (failed) return failed;
    for (int u = 0; u < F; u++) t->chamfer += f->frame_cd[u] / F, t->normal += f->frame_normal[u] / F;
    return TCB_OK;
}

/* Σ raw² over the keyframe's transforms; its gradient into tr.draw. */
static double identity_term(dyno_motion_fit *f)
{
    const float *raw = f->tr.raw + 6 * K * f->data.key;
    float *draw = f->tr.draw + 6 * K * f->data.key;
    double sum = 0;
    for (int i = 0; i < 6 * K; i++) {
        sum += (double)raw[i] * raw[i];
        draw[i] += (float)(2 * f->data.weights.identity * raw[i]);
    }
    return sum;
}

static double sigmoid(double z) { return 1 / (1 + exp(-z)); }

/* Frame u's approximate SDF s_u at its picks Y_u. */
static int sdf_frame_forward(dyno_motion_fit *f, int u, tcb_error *err)
{
    const dyno_motion_data *d = &f->data;
    size_t g = (size_t)d->n_grid_samples;
    return tcb_approx_sdf_forward(f->s + g * u, f->nbr + g * u * TCB_APPROX_SDF_K, f->Y + 3 * g * u, (int)g,
                                  d->index[u], d->pts[u], d->normals[u], TCB_APPROX_SDF_K, TCB_APPROX_SDF_RADIUS, err);
}

/* ds_u back through frame u's approximate SDF into dY_u. */
static void sdf_frame_backward(dyno_motion_fit *f, int u)
{
    const dyno_motion_data *d = &f->data;
    size_t g = (size_t)d->n_grid_samples;
    tcb_approx_sdf_backward(f->dY + 3 * g * u, f->ds + g * u, f->Y + 3 * g * u, (int)g,
                            f->nbr + g * u * TCB_APPROX_SDF_K, d->pts[u], d->normals[u], TCB_APPROX_SDF_K,
                            TCB_APPROX_SDF_RADIUS);
}

/* The SDF-sign term; its gradient into f->dY. */
static int sdf_sign_term(dyno_motion_fit *f, double *value, tcb_error *err)
{
    const dyno_motion_data *d = &f->data;
    int F = d->n_frames, g = d->n_grid_samples, failed = 0;
#pragma omp parallel for schedule(dynamic)
    for (int u = 0; u < F; u++) {
        tcb_error mine = {0};
        int rc = sdf_frame_forward(f, u, &mine);
        if (rc) {
#pragma omp critical(dyno_sdf_failure)
            if (!failed) failed = rc, *err = mine;
        }
    }
    if (failed) return failed;
    const double scale = 1.0 / (2 * DYNO_FUSION_THRES * DYNO_FUSION_THRES), mean = 1.0 / ((double)F * g);
    double sum = 0, *rho = malloc((size_t)F * sizeof *rho);
    if (!rho) return tcb_fail(err, TCB_ERR_NOMEM, "dynosurf: out of memory");
    for (int n = 0; n < g; n++) {
        double top = -INFINITY, z = 0;
        for (int u = 0; u < F; u++) {
            double s = f->s[(size_t)g * u + n];
            rho[u] = -s * s * scale, top = fmax(top, rho[u]);
        }
        for (int u = 0; u < F; u++) z += rho[u] = exp(rho[u] - top);
        double target = sigmoid(DYNO_SIGMOID_SCALE * f->yhat[n]);
        for (int u = 0; u < F; u++) {
            size_t i = (size_t)g * u + n;
            double r = rho[u] / z, sg = sigmoid(DYNO_SIGMOID_SCALE * f->s[i]), diff = r * target - r * sg;
            sum += fabs(diff) * mean;
            double sign = (diff > 0) - (diff < 0);
            f->ds[i] = (float)(-d->weights.sdf_sign * mean * sign * r * sg * (1 - sg) * DYNO_SIGMOID_SCALE);
        }
    }
    free(rho);
    *value = sum;
#pragma omp parallel for schedule(dynamic)
    for (int u = 0; u < F; u++) sdf_frame_backward(f, u);
    return TCB_OK;
}

/* The temporal smoothness of the edges; its gradient into f->dX. */
static double smooth_term(dyno_motion_fit *f)
{
    const dyno_motion_data *d = &f->data;
    size_t m = (size_t)d->n_template;
    double sum = 0, scale = d->weights.smooth / (3.0 * d->n_faces);
    static const int edges[3][2] = {{0, 1}, {1, 2}, {0, 2}};
    for (int t = 0; t < d->n_frames; t++) {
        int nbrs[2] = {t > 0 ? t - 1 : 0, t + 1 < d->n_frames ? t + 1 : d->n_frames - 1};
        for (int j = 0; j < 2; j++) {
            int u = nbrs[j];
            if (u == t) continue; /* D = 0 at the clip's ends */
            const float *Xt = f->X + 3 * m * t, *Xu = f->X + 3 * m * u;
            float *dXt = f->dX + 3 * m * t, *dXu = f->dX + 3 * m * u;
            for (int q = 0; q < d->n_faces; q++)
                for (int e = 0; e < 3; e++) {
                    size_t a = 3 * (size_t)d->faces[3 * q + edges[e][0]], b = 3 * (size_t)d->faces[3 * q + edges[e][1]];
                    for (int c = 0; c < 3; c++) {
                        double diff = ((double)Xu[a + c] - Xt[a + c]) - ((double)Xu[b + c] - Xt[b + c]);
                        sum += diff * diff;
                        float gr = (float)(2 * scale * diff);
                        dXu[a + c] += gr, dXu[b + c] -= gr, dXt[a + c] -= gr, dXt[b + c] += gr;
                    }
                }
        }
    }
    return sum / (3.0 * d->n_faces);
}

int dyno_motion_loss(dyno_motion_fit *f, const dyno_deformer *dfm, const dyno_deformer *grad, struct tcb_rng *rng,
                     dyno_motion_terms *t, tcb_error *err)
{
    const dyno_motion_data *d = &f->data;
    int F = d->n_frames;
    size_t m = (size_t)d->n_template, g = (size_t)d->n_grid_samples;
    memset(t, 0, sizeof *t);
    pick_grid(f, rng);
    deform_all(f, dfm);
    memset(f->dX, 0, (size_t)F * m * 3 * sizeof(float));
    memset(f->tr.dR, 0, (size_t)F * K * 9 * sizeof(float));
    memset(f->tr.draw, 0, (size_t)F * K * 6 * sizeof(float));
    memset(f->bt.dw, 0, m * K * sizeof(float));
    memset(f->bg.dw, 0, g * K * sizeof(float));
    int rc = chamfer_terms(f, rng, t, err);
    if (!rc) rc = sdf_sign_term(f, &t->sdf_sign, err);
    if (rc) return rc;
    t->identity = identity_term(f);
    t->smooth = smooth_term(f);
    const dyno_motion_weights *w = &d->weights;
    t->total = w->chamfer * t->chamfer + w->normal * t->normal + w->identity * t->identity +
               w->sdf_sign * t->sdf_sign + w->smooth * t->smooth;
    for (int u = 0; u < F; u++) deform_frame_backward(f, u);
    dyno_transforms_backward(dfm, grad, &f->tr);
    dyno_blend_backward(dfm, grad, &f->bt);
    dyno_blend_backward(dfm, grad, &f->bg);
    return TCB_OK;
}

void dyno_motion_frames(dyno_motion_fit *f, const dyno_deformer *dfm, float *X)
{
    const dyno_motion_data *d = &f->data;
    size_t m = (size_t)d->n_template;
    /* The blend weights once for every frame: they do not depend on t. */
    dyno_blend_forward(dfm, &f->bt, d->template_verts, d->n_template);
    dyno_transforms_forward(dfm, &f->tr, f->frames, d->n_frames);
    for (int t = 0; t < d->n_frames; t++)
        dyno_deform_apply(d->template_verts, d->n_template, f->bt.w, f->tr.R + 9 * K * t, f->tr.raw + 6 * K * t,
                          X + 3 * m * t);
}

int dyno_motion_frame_cost(dyno_motion_fit *f, struct tcb_rng *rng, int u, tcb_error *err)
{
    const dyno_motion_data *d = &f->data;
    size_t m = (size_t)d->n_template, ms = (size_t)d->n_samples;
    if (u < 0 || u >= d->n_frames) return tcb_fail(err, TCB_ERR_INTERNAL, "dynosurf: no frame %d", u);
    deform_frame(f, u);
    memset(f->dX + 3 * m * u, 0, 3 * m * sizeof(float));
    int rc = tcb_mesh_sample_draw(f->X + 3 * m * u, d->faces, d->n_faces, (int)ms, rng, f->draws + ms * u, err);
    if (!rc) rc = chamfer_frame(f, u, 0, (float)(d->weights.chamfer / d->n_frames),
                                (float)(d->weights.normal / d->n_frames), err);
    if (!rc) rc = sdf_frame_forward(f, u, err);
    if (rc) return rc;
    sdf_frame_backward(f, u);
    deform_frame_backward(f, u);
    return TCB_OK;
}
