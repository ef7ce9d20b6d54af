/* DynoSurf's shape network (github yaoyx689/DynoSurf @ a2b7324:
 * code/model/dmtet_network.py Decoder, code/trainer.py L67-79): at each
 * grid vertex x, an SDF value and a bounded offset of the vertex.
 *
 *   e = posenc(x)            [n][33]   (5 frequencies 1…16, input kept)
 *   h1 = lrelu(W1 e)         [n][128]  (no biases anywhere; slope 0.01)
 *   h2..h5 = lrelu(Wk h)     [n][128]
 *   o = W6 h5                [n][4]
 *   sdf = o[:, 0]; v = x + tanh(o[:, 1:4]) · edge   (edge: dyno_tet_edge_bound)
 *
 * Parameters W1 … W6 in one flat buffer, each [out][in] (PyTorch's layout),
 * initialised as PyTorch's Linear (U(±1/√in)). The network is evaluated at
 * the grid's undeformed vertices; the SDF is positive outside. */
#ifndef TCB_DYNOSURF_SHAPE_H
#define TCB_DYNOSURF_SHAPE_H

#include <stddef.h>

#include "neural/mlp.h"
#include "tcb/error.h"

#define DYNO_SHAPE_FREQS 5
#define DYNO_SHAPE_IN 33 /* 3 · (1 + 2 · DYNO_SHAPE_FREQS) */
#define DYNO_SHAPE_WIDTH 128
#define DYNO_SHAPE_LAYERS 6
#define DYNO_SHAPE_OUT 4
#define DYNO_LEAKY_SLOPE 0.01f

typedef struct dyno_shape {
    tcb_mlp net;
} dyno_shape;

/* Floats in the flat parameter buffer. */
size_t dyno_shape_size(void);

/* Views s into params (or into a gradient buffer of the same size). */
void dyno_shape_bind(dyno_shape *s, float *params);

struct tcb_rng;
void dyno_shape_init(const dyno_shape *s, struct tcb_rng *rng);

/* What the backward pass needs of a forward over n vertices. */
typedef struct dyno_shape_acts {
    int n;
    float *enc;       /* [n][33] */
    tcb_mlp_acts mlp; /* [n][128] after each LeakyReLU */
    float *out;       /* [n][4] */
} dyno_shape_acts;

int dyno_shape_acts_alloc(dyno_shape_acts *a, int n, tcb_error *err);
void dyno_shape_acts_free(dyno_shape_acts *a);

/* a->out for the vertices x [a->n][3]. */
void dyno_shape_forward(const dyno_shape *s, dyno_shape_acts *a, const float *x);

/* grad's weights += ∂L/∂W for ∂L/∂out = dout [a->n][4], after the forward
 * that filled a. */
void dyno_shape_backward(const dyno_shape *s, const dyno_shape *grad, dyno_shape_acts *a, const float *dout);

/* The template's grid: sdf [n] and deformed vertices v [n][3] from out. */
void dyno_shape_readout(const float *out, const float *x, int n, float edge, float *sdf, float *v);

/* dout [n][4] from ∂L/∂sdf and ∂L/∂v (either may be NULL: zero). */
void dyno_shape_readout_backward(const float *out, int n, float edge, const float *dsdf, const float *dv, float *dout);

#endif
