/* The bias-free MLP (neural/mlp.h). */
#include "neural/mlp.h"

#include <stdlib.h>
#include <string.h>

static int width_in(int l, int in, int width) { return l == 0 ? in : width; }

size_t tcb_mlp_size(int in, int width, int out, int n_layers)
{
    return (size_t)in * width + (size_t)(n_layers - 2) * width * width + (size_t)width * out;
}

void tcb_mlp_bind(tcb_mlp *m, float *params, size_t *offset, int in, int width, int out, int n_layers,
                  float slope)
{
    m->n_layers = n_layers, m->slope = slope;
    for (int l = 0; l < n_layers; l++)
        tcb_linear_bind_nobias(&m->layer[l], params, offset, width_in(l, in, width), l == n_layers - 1 ? out : width);
}

void tcb_mlp_init(const tcb_mlp *m, struct tcb_rng *rng)
{
    for (int l = 0; l < m->n_layers; l++) tcb_linear_init_uniform(&m->layer[l], rng);
}

int tcb_mlp_acts_alloc(tcb_mlp_acts *a, int width, int n_layers, int capacity, tcb_error *err)
{
    memset(a, 0, sizeof *a);
    a->capacity = capacity;
    size_t wide = (size_t)capacity * width * sizeof(float);
    int ok = 1;
    for (int l = 0; l < n_layers - 1; l++) ok &= (a->h[l] = malloc(wide)) != NULL;
    for (int k = 0; k < 2; k++) ok &= (a->dh[k] = malloc(wide)) != NULL;
    if (ok) return TCB_OK;
    tcb_mlp_acts_free(a);
    return tcb_fail(err, TCB_ERR_NOMEM, "out of memory for a network's activations over %d rows", capacity);
}

void tcb_mlp_acts_free(tcb_mlp_acts *a)
{
    for (int l = 0; l < TCB_MLP_LAYERS_MAX - 1; l++) free(a->h[l]);
    for (int k = 0; k < 2; k++) free(a->dh[k]);
    memset(a, 0, sizeof *a);
}

static void activate(const tcb_mlp *m, float *h, int64_t n)
{
    if (m->slope > 0) tcb_leaky_relu_forward(h, h, n, m->slope);
    else tcb_relu_forward(h, h, n);
}

static void activate_backward(const tcb_mlp *m, float *d, const float *h, int64_t n)
{
    if (m->slope > 0) tcb_leaky_relu_backward(d, d, h, n, m->slope);
    else tcb_relu_backward(d, d, h, n);
}

void tcb_mlp_forward(const tcb_mlp *m, tcb_mlp_acts *a, const float *x, int rows, float *y)
{
    a->rows = rows;
    const float *in = x;
    for (int l = 0; l < m->n_layers - 1; l++) {
        const tcb_linear *L = &m->layer[l];
        tcb_linear_forward(a->h[l], in, L->W, NULL, rows, 0, L->in, L->out);
        activate(m, a->h[l], (int64_t)rows * L->out);
        in = a->h[l];
    }
    const tcb_linear *L = &m->layer[m->n_layers - 1];
    tcb_linear_forward(y, in, L->W, NULL, rows, 0, L->in, L->out);
}

void tcb_mlp_backward(const tcb_mlp *m, const tcb_mlp *grad, tcb_mlp_acts *a, const float *x, const float *dy,
                      float *dx)
{
    int rows = a->rows;
    /* d: the gradient at the current layer's output; the ping-pong
     * buffers dh[0], dh[1] carry it down. */
    const float *d = dy;
    float *next = a->dh[0];
    for (int l = m->n_layers - 1; l >= 0; l--) {
        const tcb_linear *L = &m->layer[l];
        const float *in = l == 0 ? x : a->h[l - 1];
        tcb_linear_backward(l == 0 ? dx : next, grad->layer[l].W, NULL, d, in, L->W, rows, 0, L->in, L->out);
        if (l == 0) break;
        activate_backward(m, next, a->h[l - 1], (int64_t)rows * L->in);
        d = next;
        next = next == a->dh[0] ? a->dh[1] : a->dh[0];
    }
}
