/* DynoSurf's shape network (methods/dynosurf/shape.h). */
#include "methods/dynosurf/shape.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "neural/posenc.h"

_Static_assert(DYNO_SHAPE_IN == 3 * (1 + 2 * DYNO_SHAPE_FREQS), "the encoding's width");

size_t dyno_shape_size(void)
{
    return tcb_mlp_size(DYNO_SHAPE_IN, DYNO_SHAPE_WIDTH, DYNO_SHAPE_OUT, DYNO_SHAPE_LAYERS);
}

void dyno_shape_bind(dyno_shape *s, float *params)
{
    size_t offset = 0;
    tcb_mlp_bind(&s->net, params, &offset, DYNO_SHAPE_IN, DYNO_SHAPE_WIDTH, DYNO_SHAPE_OUT, DYNO_SHAPE_LAYERS,
                 DYNO_LEAKY_SLOPE);
}

void dyno_shape_init(const dyno_shape *s, struct tcb_rng *rng) { tcb_mlp_init(&s->net, rng); }

int dyno_shape_acts_alloc(dyno_shape_acts *a, int n, tcb_error *err)
{
    memset(a, 0, sizeof *a);
    a->n = n;
    a->enc = malloc((size_t)n * DYNO_SHAPE_IN * sizeof(float));
    a->out = malloc((size_t)n * DYNO_SHAPE_OUT * sizeof(float));
    if (a->enc && a->out && !tcb_mlp_acts_alloc(&a->mlp, DYNO_SHAPE_WIDTH, DYNO_SHAPE_LAYERS, n, err))
        return TCB_OK;
    dyno_shape_acts_free(a);
    return tcb_fail(err, TCB_ERR_NOMEM, "dynosurf: out of memory for the shape network over %d vertices", n);
}

void dyno_shape_acts_free(dyno_shape_acts *a)
{
    free(a->enc), free(a->out);
    tcb_mlp_acts_free(&a->mlp);
    memset(a, 0, sizeof *a);
}

void dyno_shape_forward(const dyno_shape *s, dyno_shape_acts *a, const float *x)
{
    tcb_posenc_forward(x, a->n, 3, DYNO_SHAPE_FREQS, a->enc);
    tcb_mlp_forward(&s->net, &a->mlp, a->enc, a->n, a->out);
}

void dyno_shape_backward(const dyno_shape *s, const dyno_shape *grad, dyno_shape_acts *a, const float *dout)
{
    tcb_mlp_backward(&s->net, &grad->net, &a->mlp, a->enc, dout, NULL);
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
