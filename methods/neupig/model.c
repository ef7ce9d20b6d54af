/* Neu-PiG's deformation model: forward, loss and gradient
 * (methods/neupig/model.h). */
#include "methods/neupig/model.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "methods/neupig/loss.h"
#include "neural/fourier_time.h"
#include "neural/lattice.h"
#include "neural/rigid.h"
#include "neural/robust_chamfer.h"

tcb_neupig_arch tcb_neupig_arch_reference(void)
{
    return (tcb_neupig_arch){8, 2, 3, 30, 4, 2, 4, 512, 0.4, 1.5, 0.4, 100.0, 0.3, TCB_SOBOLEV_PCGRID};
}

static int mlp_in(const tcb_neupig_arch *a)
{
    return a->features + a->normal_features + 2 * a->time_freqs;
}

static size_t mlp_size(const tcb_neupig_arch *a)
{
    size_t in = (size_t)mlp_in(a), h = (size_t)a->hidden;
    return in * h + h + h * h + h + h * TCB_RIGID_OUT + TCB_RIGID_OUT;
}

int tcb_neupig_model_init(tcb_neupig_model *m, const tcb_neupig_arch *a, tcb_error *err)
{
    memset(m, 0, sizeof *m);
    if (a->levels < 1 || a->levels > TCB_NEUPIG_MAX_LEVELS || a->base_res < 2 || a->res_step < 0 ||
        a->features < 1 || a->normal_res < 2 || a->normal_features < 1 || a->time_freqs < 1 ||
        a->hidden < 1)
        return tcb_fail(err, TCB_ERR_INPUT, "neupig: invalid architecture (levels %d, base_res %d)",
                        a->levels, a->base_res);
    m->a = *a;
    m->grids = a->levels + 1;
    for (int g = 0; g < m->grids; g++) {
        int normal = g == a->levels;
        m->res[g] = normal ? a->normal_res : a->base_res + g * a->res_step;
        m->width[g] = normal ? a->normal_features : a->features;
        double lambda = normal ? a->normal_lambda : a->lambda * pow(a->lambda_growth, g);
        size_t r = (size_t)m->res[g];
        m->grid_off[g + 1] = m->grid_off[g] + r * r * r * (size_t)m->width[g];
        int rc = tcb_sobolev_init(&m->sobolev[g], m->res[g], lambda, a->laplacian, err);
        if (rc) {
            tcb_neupig_model_free(m);
            return rc;
        }
    }
    m->n_params = m->grid_off[m->grids] + mlp_size(a);
    return TCB_OK;
}

void tcb_neupig_model_free(tcb_neupig_model *m)
{
    for (int g = 0; g < m->grids; g++) tcb_sobolev_free(&m->sobolev[g]);
    memset(m, 0, sizeof *m);
}

void tcb_neupig_mlp_view(const tcb_neupig_model *m, float *params, tcb_linear layers[3])
{
    size_t off = m->grid_off[m->grids];
    tcb_linear_bind(&layers[0], params, &off, mlp_in(&m->a), m->a.hidden);
    tcb_linear_bind(&layers[1], params, &off, m->a.hidden, m->a.hidden);
    tcb_linear_bind(&layers[2], params, &off, m->a.hidden, TCB_RIGID_OUT);
}

void tcb_neupig_params_init(const tcb_neupig_model *m, float *params, tcb_rng *rng)
{
    memset(params, 0, m->n_params * sizeof *params);
    tcb_linear l[3];
    tcb_neupig_mlp_view(m, params, l);
    tcb_linear_init_uniform(&l[0], rng);
    tcb_linear_init_uniform(&l[1], rng);
}

static size_t largest_grid(const tcb_neupig_model *m)
{
    size_t n = 0;
    for (int g = 0; g < m->grids; g++)
        if (m->grid_off[g + 1] - m->grid_off[g] > n) n = m->grid_off[g + 1] - m->grid_off[g];
    return n;
}

void tcb_neupig_work_free(tcb_neupig_work *w)
{
    free(w->feat_p), free(w->feat_n), free(w->x0), free(w->h1), free(w->h2), free(w->o);
    free(w->X), free(w->dX), free(w->dout), free(w->dh), free(w->dx0);
    free(w->dfeat_p), free(w->dfeat_n), free(w->values), free(w->scratch), free(w->cd);
    memset(w, 0, sizeof *w);
}

int tcb_neupig_work_init(tcb_neupig_work *w, const tcb_neupig_model *m, const tcb_neupig_problem *p,
                         tcb_error *err)
{
    memset(w, 0, sizeof *w);
    if (p->T < 2 || p->T > TCB_NEUPIG_MAX_FRAMES || p->nv < 1 || p->key < 0 || p->key >= p->T)
        return tcb_fail(err, TCB_ERR_INPUT, "neupig: %d frames (2 to %d), %d template vertices, keyframe %d",
                        p->T, TCB_NEUPIG_MAX_FRAMES, p->nv, p->key);
    size_t nv = (size_t)p->nv, rows = (size_t)p->T * nv, H = (size_t)m->a.hidden;
    size_t F = (size_t)m->a.features, Fn = (size_t)m->a.normal_features, in = (size_t)mlp_in(&m->a);
    size_t grid = largest_grid(m);
    w->T = p->T, w->nv = p->nv, w->rows = (int)rows;
    w->feat_p = malloc(nv * F * sizeof(float));
    w->feat_n = malloc(nv * Fn * sizeof(float));
    w->x0 = malloc(rows * in * sizeof(float));
    w->h1 = malloc(rows * H * sizeof(float));
    w->h2 = malloc(rows * H * sizeof(float));
    w->o = malloc(rows * TCB_RIGID_OUT * sizeof(float));
    w->X = malloc(rows * 3 * sizeof(float));
    w->dX = malloc(rows * 3 * sizeof(float));
    w->dout = malloc(rows * TCB_RIGID_OUT * sizeof(float));
    w->dh = malloc(rows * H * sizeof(float));
    w->dx0 = malloc(rows * in * sizeof(float));
    w->dfeat_p = malloc(nv * F * sizeof(float));
    w->dfeat_n = malloc(nv * Fn * sizeof(float));
    w->values = malloc(grid * sizeof(float));
    w->scratch = malloc(grid * sizeof(double));
    w->cd = malloc((size_t)p->T * sizeof(double));
    if (!w->feat_p || !w->feat_n || !w->x0 || !w->h1 || !w->h2 || !w->o || !w->X || !w->dX ||
        !w->dout || !w->dh || !w->dx0 || !w->dfeat_p || !w->dfeat_n || !w->values || !w->scratch ||
        !w->cd) {
        tcb_neupig_work_free(w);
        return tcb_fail(err, TCB_ERR_NOMEM, "neupig: out of memory for %d frames × %d vertices",
                        p->T, p->nv);
    }
    return TCB_OK;
}

/* feat [nv][width] = tanh(Σ over the grids of one kind of their samples at
 * pts, position levels averaged). */
static void grid_features(const tcb_neupig_model *m, const float *params, int first, int last,
                          const float *pts, int nv, tcb_neupig_work *w, float *feat)
{
    int width = m->width[first];
    memset(feat, 0, (size_t)nv * (size_t)width * sizeof *feat);
    float scale = 1.0f / (float)(last - first);
    for (int g = first; g < last; g++) {
        tcb_sobolev_solve(&m->sobolev[g], width, params + m->grid_off[g], w->values, w->scratch);
        tcb_lattice_forward(feat, w->values, m->res[g], width, pts, nv, scale);
    }
    for (size_t i = 0; i < (size_t)nv * (size_t)width; i++) feat[i] = tanhf(feat[i]);
}

static void forward(const tcb_neupig_model *m, const float *params, const tcb_neupig_problem *p,
                    tcb_neupig_work *w, float *X)
{
    const tcb_neupig_arch *a = &m->a;
    int nv = p->nv, in = mlp_in(a), F = a->features, Fn = a->normal_features;
    grid_features(m, params, 0, a->levels, p->verts, nv, w, w->feat_p);
    grid_features(m, params, a->levels, m->grids, p->normals, nv, w, w->feat_n);
    for (int t = 0; t < p->T; t++) {
        float time[64];
        tcb_fourier_time((double)t / (p->T - 1), a->time_freqs, time);
        for (int v = 0; v < nv; v++) {
            float *x = w->x0 + ((size_t)t * nv + v) * (size_t)in;
            memcpy(x, w->feat_p + (size_t)v * F, (size_t)F * sizeof *x);
            memcpy(x + F, w->feat_n + (size_t)v * Fn, (size_t)Fn * sizeof *x);
            memcpy(x + F + Fn, time, 2 * (size_t)a->time_freqs * sizeof *x);
        }
    }
    tcb_linear l[3];
    tcb_neupig_mlp_view(m, (float *)params, l);
    int64_t hn = (int64_t)w->rows * a->hidden;
    tcb_linear_forward(w->h1, w->x0, l[0].W, l[0].b, w->rows, 0, in, a->hidden);
    tcb_leaky_relu_forward(w->h1, w->h1, hn, TCB_NEUPIG_LEAKY_SLOPE);
    tcb_linear_forward(w->h2, w->h1, l[1].W, l[1].b, w->rows, 0, a->hidden, a->hidden);
    tcb_leaky_relu_forward(w->h2, w->h2, hn, TCB_NEUPIG_LEAKY_SLOPE);
    tcb_linear_forward(w->o, w->h2, l[2].W, l[2].b, w->rows, 0, a->hidden, TCB_RIGID_OUT);
    tcb_rigid_forward(X, w->o, p->verts, w->rows, nv);
}

/* w made for p's sizes (a work outlives its problem only by mistake). */
static int work_fits(const tcb_neupig_work *w, const tcb_neupig_problem *p, tcb_error *err)
{
    if (w->T == p->T && w->nv == p->nv) return TCB_OK;
    return tcb_fail(err, TCB_ERR_INTERNAL, "neupig: work for %d frames × %d vertices, problem %d × %d", w->T,
                    w->nv, p->T, p->nv);
}

int tcb_neupig_deform(const tcb_neupig_model *m, const float *params, const tcb_neupig_problem *p,
                      tcb_neupig_work *w, float *X, tcb_error *err)
{
    int rc = work_fits(w, p, err);
    if (!rc) forward(m, params, p, w, X);
    return rc;
}

/* dX [T][nv][3] of the loss; fills out and cd. */
static int loss_backward(const tcb_neupig_model *m, const tcb_neupig_problem *p, const float *X,
                         long long epoch, long long epochs, tcb_neupig_loss *out, double *cd,
                         float *dX, tcb_error *err)
{
    size_t frame = (size_t)p->nv * 3;
    double conf[TCB_NEUPIG_MAX_FRAMES];
    for (int t = 0; t < p->T; t++) {
        int rc = tcb_robust_chamfer(X + t * frame, p->nv, p->points[t], p->n_points[t],
                                    p->points_index[t], m->a.welsch_alpha, &cd[t], dX + t * frame, err);
        if (rc) return rc;
    }
    tcb_neupig_confidence(cd, p->T, p->key, epoch, epochs, conf);
    out->chamfer = 0.0;
    for (int t = 0; t < p->T; t++) {
        out->chamfer += conf[t] * cd[t] / p->T;
        float s = (float)(conf[t] / p->T);
        for (size_t i = 0; i < frame; i++) dX[t * frame + i] *= s;
    }
    out->edge = tcb_neupig_edge_l1(X, p->T, p->nv, p->edges, p->ne, p->edge_len, m->a.edge_weight, dX);
    out->total = out->chamfer + out->edge;
    return TCB_OK;
}

/* The grids' gradients from dfeat (∂ℓ/∂ of the tanh outputs, overwritten). */
static void grid_backward(const tcb_neupig_model *m, int first, int last, const float *pts, int nv,
                          const float *feat, float *dfeat, tcb_neupig_work *w, float *grads)
{
    int width = m->width[first];
    for (size_t i = 0; i < (size_t)nv * (size_t)width; i++) dfeat[i] *= 1.0f - feat[i] * feat[i];
    float scale = 1.0f / (float)(last - first);
    for (int g = first; g < last; g++) {
        size_t r = (size_t)m->res[g];
        memset(w->values, 0, r * r * r * (size_t)width * sizeof(float));
        tcb_lattice_backward(w->values, dfeat, m->res[g], width, pts, nv, scale);
        tcb_sobolev_solve(&m->sobolev[g], width, w->values, grads + m->grid_off[g], w->scratch);
    }
}

/* The features' gradients: Σ over frames of the MLP input's gradient. */
static void feature_grads(const tcb_neupig_model *m, const tcb_neupig_problem *p, const float *dx0,
                          float *dfeat_p, float *dfeat_n)
{
    int F = m->a.features, Fn = m->a.normal_features, in = mlp_in(&m->a), nv = p->nv;
    memset(dfeat_p, 0, (size_t)nv * F * sizeof *dfeat_p);
    memset(dfeat_n, 0, (size_t)nv * Fn * sizeof *dfeat_n);
    for (int t = 0; t < p->T; t++)
        for (int v = 0; v < nv; v++) {
            const float *d = dx0 + ((size_t)t * nv + v) * (size_t)in;
            for (int f = 0; f < F; f++) dfeat_p[(size_t)v * F + f] += d[f];
            for (int f = 0; f < Fn; f++) dfeat_n[(size_t)v * Fn + f] += d[F + f];
        }
}

/* Back through the MLP and the grids, from w->dX; w's activations are
 * overwritten once their values are spent. */
static void backward(const tcb_neupig_model *m, const float *params, const tcb_neupig_problem *p,
                     tcb_neupig_work *w, float *grads)
{
    const tcb_neupig_arch *a = &m->a;
    int in = mlp_in(a);
    int64_t hn = (int64_t)w->rows * a->hidden;
    tcb_linear l[3], g[3];
    tcb_neupig_mlp_view(m, (float *)params, l);
    tcb_neupig_mlp_view(m, grads, g);
    tcb_rigid_backward(w->dout, w->dX, w->o, p->verts, w->rows, p->nv);
    tcb_linear_backward(w->dh, g[2].W, g[2].b, w->dout, w->h2, l[2].W, w->rows, 0, a->hidden, TCB_RIGID_OUT);
    tcb_leaky_relu_backward(w->dh, w->dh, w->h2, hn, TCB_NEUPIG_LEAKY_SLOPE);
    tcb_linear_backward(w->h2, g[1].W, g[1].b, w->dh, w->h1, l[1].W, w->rows, 0, a->hidden, a->hidden);
    tcb_leaky_relu_backward(w->h2, w->h2, w->h1, hn, TCB_NEUPIG_LEAKY_SLOPE);
    tcb_linear_backward(w->dx0, g[0].W, g[0].b, w->h2, w->x0, l[0].W, w->rows, 0, in, a->hidden);
    feature_grads(m, p, w->dx0, w->dfeat_p, w->dfeat_n);
    grid_backward(m, 0, a->levels, p->verts, p->nv, w->feat_p, w->dfeat_p, w, grads);
    grid_backward(m, a->levels, m->grids, p->normals, p->nv, w->feat_n, w->dfeat_n, w, grads);
}

int tcb_neupig_loss_grad(const tcb_neupig_model *m, const float *params,
                         const tcb_neupig_problem *p, tcb_neupig_work *w, long long epoch,
                         long long epochs, tcb_neupig_loss *out, float *grads, tcb_error *err)
{
    int rc = work_fits(w, p, err);
    if (rc) return rc;
    forward(m, params, p, w, w->X);
    rc = loss_backward(m, p, w->X, epoch, epochs, out, w->cd, w->dX, err);
    if (rc) return rc;
    memset(grads, 0, m->n_params * sizeof *grads);
    backward(m, params, p, w, grads);
    return TCB_OK;
}
