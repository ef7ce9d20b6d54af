/* A bias-free multilayer perceptron, as DynoSurf builds all three of its
 * networks (github yaoyx689/DynoSurf @ a2b7324: code/model/dmtet_network.py
 * Decoder, code/model/deformer_network.py ControlPts_deformer's transform
 * MLP and lw_net): Linear(bias=False) layers in → width → … → width → out
 * with a ReLU (slope 0) or LeakyReLU (slope > 0) after each but the last.
 *
 *   h_1 = act(W_1 x)           [rows][width]
 *   h_l = act(W_l h_{l−1})     [rows][width], l = 2 … L−1
 *   y   = W_L h_{L−1}          [rows][out]
 *
 * Weights [out][in] (PyTorch's layout) in order in a flat buffer,
 * initialised as PyTorch's Linear (U(±1/√in)). */
#ifndef TCB_NEURAL_MLP_H
#define TCB_NEURAL_MLP_H

#include <stddef.h>

#include "neural/layers.h"
#include "tcb/error.h"

#define TCB_MLP_LAYERS_MAX 8

typedef struct tcb_mlp {
    int n_layers;
    float slope; /* 0: ReLU */
    tcb_linear layer[TCB_MLP_LAYERS_MAX];
} tcb_mlp;

/* Floats of an MLP's weights. */
size_t tcb_mlp_size(int in, int width, int out, int n_layers);

/* Views m at params + *offset and advances *offset (2 ≤ n_layers ≤ TCB_MLP_LAYERS_MAX). */
void tcb_mlp_bind(tcb_mlp *m, float *params, size_t *offset, int in, int width, int out, int n_layers,
                  float slope);

struct tcb_rng;
void tcb_mlp_init(const tcb_mlp *m, struct tcb_rng *rng);

/* The hidden activations of a forward over up to `capacity` rows, and the
 * backward's scratch. */
typedef struct tcb_mlp_acts {
    int capacity, rows;
    float *h[TCB_MLP_LAYERS_MAX - 1]; /* [rows][width] after each activation */
    float *dh[2];                     /* [rows][width] */
} tcb_mlp_acts;

int tcb_mlp_acts_alloc(tcb_mlp_acts *a, int width, int n_layers, int capacity, tcb_error *err);
void tcb_mlp_acts_free(tcb_mlp_acts *a);

/* y [rows][out] of x [rows][in]; rows ≤ a->capacity. */
void tcb_mlp_forward(const tcb_mlp *m, tcb_mlp_acts *a, const float *x, int rows, float *y);

/* grad's weights += ∂L/∂W for dy = ∂L/∂y [rows][out] after the forward of
 * x that filled a; dx [rows][in] = ∂L/∂x when not NULL. */
void tcb_mlp_backward(const tcb_mlp *m, const tcb_mlp *grad, tcb_mlp_acts *a, const float *x, const float *dy,
                      float *dx);

#endif
