/* DynoSurf's shape network (methods/dynosurf/shape.h). */
#include "methods/dynosurf/shape.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "neural/posenc.h"

_Static_assert(DYNO_SHAPE_IN == 3 * (1 + 2 * DYNO_SHAPE_FREQS), "the encoding's width");

static int layer_in(int l) { return l == 0 ? DYNO_SHAPE_IN : DYNO_SHAPE_WIDTH; }
static int layer_out(int l) { return l == DYNO_SHAPE_LAYERS - 1 ? DYNO_SHAPE_OUT : DYNO_SHAPE_WIDTH; }

size_t dyno_shape_size(void)
{
    size_t total = 0;
    for (int l = 0; l < DYNO_SHAPE_LAYERS; l++) total += (size_t)layer_in(l) * layer_out(l);
    return total;
}

void dyno_shape_bind(dyno_shape *s, float *params)
{
    size_t offset = 0;
    for (int l = 0; l < DYNO_SHAPE_LAYERS; l++) tcb_linear_bind_nobias(&s->layer[l], params, &offset, layer_in(l), layer_out(l));
}

void dyno_shape_init(const dyno_shape *s, struct tcb_rng *rng)
{
    for (int l = 0; l < DYNO_SHAPE_LAYERS; l++) tcb_linear_init_uniform(&s->layer[l], rng);
}

int dyno_shape_acts_alloc(dyno_shape_acts *a, int n, tcb_error *err)
{
    memset(a, 0, sizeof *a);
    a->n = n;
    size_t wide = (size_t)n * DYNO_SHAPE_WIDTH * sizeof(float);
    a->enc = malloc((size_t)n * DYNO_SHAPE_IN * sizeof(float));
    a->out = malloc((size_t)n * DYNO_SHAPE_OUT * sizeof(float));
    int ok = a->enc && a->out;
    for (int l = 0; l < DYNO_SHAPE_LAYERS - 1; l++) ok &= (a->h[l] = malloc(wide)) != NULL;
    for (int k = 0; k < 2; k++) ok &= (a->dh[k] = malloc(wide)) != NULL;
    if (ok) return TCB_OK;
    dyno_shape_acts_free(a);
    return tcb_fail(err, TCB_ERR_NOMEM, "dynosurf: out of memory for the shape network over %d vertices", n);
}

void dyno_shape_acts_free(dyno_shape_acts *a)
{
    free(a->enc), free(a->out);
    for (int l = 0; l < DYNO_SHAPE_LAYERS - 1; l++) free(a->h[l]);
    for (int k = 0; k < 2; k++) free(a->dh[k]);
    memset(a, 0, sizeof *a);
}

void dyno_shape_forward(const dyno_shape *s, dyno_shape_acts *a, const float *x)
{
    int n = a->n;
    tcb_posenc_forward(x, n, 3, DYNO_SHAPE_FREQS, a->enc);
    const float *in = a->enc;
    for (int l = 0; l < DYNO_SHAPE_LAYERS - 1; l++) {
        const tcb_linear *L = &s->layer[l];
        tcb_linear_forward(a->h[l], in, L->W, NULL, n, 0, L->in, L->out);
        tcb_leaky_relu_forward(a->h[l], a->h[l], (int64_t)n * L->out, DYNO_LEAKY_SLOPE);
        in = a->h[l];
    }
    const tcb_linear *L = &s->layer[DYNO_SHAPE_LAYERS - 1];
    tcb_linear_forward(a->out, in, L->W, NULL, n, 0, L->in, L->out);
}

void dyno_shape_backward(const dyno_shape *s, const dyno_shape *grad, dyno_shape_acts *a, const float *dout)
{
    int n = a->n, last = DYNO_SHAPE_LAYERS - 1;
    /* dy: the gradient at the current layer's output; the ping-pong
     * buffers dh[0], dh[1] carry it down. */
    const float *dy = dout;
    float *dx = a->dh[0];
    for (int l = last; l >= 0; l--) {
        const tcb_linear *L = &s->layer[l];
        const float *x = l == 0 ? a->enc : a->h[l - 1];
        tcb_linear_backward(l == 0 ? NULL : dx, grad->layer[l].W, NULL, dy, x, L->W, n, 0, L->in, L->out);
        if (l == 0) break;
        /* through the LeakyReLU that made x */
        tcb_leaky_relu_backward(dx, dx, a->h[l - 1], (int64_t)n * L->in, DYNO_LEAKY_SLOPE);
        dy = dx;
        dx = dx == a->dh[0] ? a->dh[1] : a->dh[0];
    }
}

void dyno_shape_readout(const float *out, const float *x, int n, float edge, float *sdf, float *v)
{
    for (size_t i = 0; i < (size_t)n; i++) {
        const float *o = out + DYNO_SHAPE_OUT * i;
        sdf[i] = o[0];
        for (int k = 0; k < 3; k++) v[3 * i + k] = x[3 * i + k] + tanhf(o[1 + k]) * edge;
    }
}

void dyno_shape_readout_backward(const float *out, int n, float edge, const float *dsdf, const float *dv, float *dout)
{
    for (size_t i = 0; i < (size_t)n; i++) {
        const float *o = out + DYNO_SHAPE_OUT * i;
        float *d = dout + DYNO_SHAPE_OUT * i;
        d[0] = dsdf ? dsdf[i] : 0.0f;
        for (int k = 0; k < 3; k++) {
            float t = tanhf(o[1 + k]);
            d[1 + k] = dv ? dv[3 * i + k] * edge * (1.0f - t * t) : 0.0f;
        }
    }
}
