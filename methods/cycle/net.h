/* The CC network (Groueix et al. SGP'19; CC code AE_Meta_AtlasNet with
 * MetaPointGenCon2, auxiliary/model.py; reference-protocol §3.6), which
 * deforms a source cloud X towards a target cloud Y:
 *
 *   encoders   two PointNets with batch norm, one for X, one for Y
 *              (PointNetfeat, STN off): per point 3→64 BN ReLU →128 BN ReLU
 *              →C BN, max-pool over the points, then C→Z BN ReLU.
 *   predictor  MetaVector on [z_X, z_Y]: 2Z→Z BN ReLU →Z/2 BN ReLU →K,
 *              the weights of the meta-MLP, per shape.
 *   meta-MLP   L+1 meta layers applied to every point x of X as a row
 *              vector, with d_in = [3, H × L], d_out = [H × L, 3]:
 *                  h ← ReLU(BN0((h + b)·(W + I))),  h ← act(BN1(conv(h)))
 *              W (d_in × d_in, row-major) and b (d_in) are the predicted
 *              slice of the layer; conv is a fixed d_in→d_out linear map;
 *              act is ReLU with BN1, and tanh without BN1 on the last
 *              layer. The output is 2·tanh(·): an absolute position in
 *              (−2, 2); with `residual`, x + 2·tanh(·), an offset.
 *   K = 12 + L·(H² + H): 24,972 at the CC code's H 64, L 6.
 *
 * Layout. The trained parameters live in ONE flat float vector (and their
 * gradients in a second of the same layout), the batch-norm running
 * statistics in a third ("buffers"): the optimizer and the checkpoints
 * treat them as flat vectors, the structs below are named views. Tensor
 * order: encoder X (conv1, bn1, conv2, bn2, conv3, bn3, fc, bnf), encoder Y
 * (the same), predictor (fc1, bn1, fc2, bn2, fc3), meta layers 0..L (bn0,
 * conv, bn1 except on the last). Linear weights [out][in] then bias [out],
 * batch norms γ then β (PyTorch's weight, bias); buffers running mean then
 * variance per batch norm, in the same order. */
#ifndef TCB_CC_NET_H
#define TCB_CC_NET_H

#include <stddef.h>

#include "neural/batchnorm.h"
#include "neural/layers.h"
#include "neural/weights.h"
#include "tcb/error.h"
#include "tcb/rng.h"

/* The CC code's sizes are C 1024, Z 512, H 64, L 6 (the `paper` preset). */
typedef struct tcb_cc_dims {
    int C; /* PointNet's last per-point width */
    int Z; /* latent size of each encoder; Z even */
    int H; /* meta-MLP hidden width */
    int L; /* meta-MLP hidden layers: L + 1 meta layers */
    int residual; /* 1: out = x + 2·tanh(·), the CC code's skip_connections
                   * (forward_resnet); 0: the absolute position 2·tanh(·) the
                   * CC code trains (its training path, forward_classic_with_
                   * latent, bypasses the skip). Not a trained tensor. */
} tcb_cc_dims;

#define TCB_CC_ENC1 64  /* PointNet's first two widths, fixed as in the CC code */
#define TCB_CC_ENC2 128
#define TCB_CC_MAX_META 33 /* L ≤ 32 */

typedef struct tcb_cc_encoder {
    tcb_linear conv1, conv2, conv3, fc; /* 3→64, 64→128, 128→C, C→Z */
    tcb_batchnorm bn1, bn2, bn3, bnf;
} tcb_cc_encoder;

typedef struct tcb_cc_predictor {
    tcb_linear fc1, fc2, fc3; /* 2Z→Z, Z→Z/2, Z/2→K */
    tcb_batchnorm bn1, bn2;
} tcb_cc_predictor;

typedef struct tcb_cc_meta_layer {
    int din, dout;
    size_t w_at, b_at;  /* its W [din][din] and b [din] inside a shape's K predicted values */
    tcb_batchnorm bn0;  /* [din] */
    tcb_linear conv;    /* din → dout */
    tcb_batchnorm bn1;  /* [dout]; C = 0 on the last layer (tanh, no BN) */
} tcb_cc_meta_layer;

/* A set of views into one flat vector (parameters or gradients). */
typedef struct tcb_cc_views {
    tcb_cc_encoder enc[2]; /* [0] encodes the source X, [1] the target Y */
    tcb_cc_predictor pred;
    tcb_cc_meta_layer meta[TCB_CC_MAX_META];
} tcb_cc_views;

typedef struct tcb_cc_net {
    tcb_cc_dims d;
    int n_meta;         /* L + 1 */
    size_t K;           /* predicted values per shape */
    size_t nparams, nbuffers;
    float *params, *grads; /* [nparams] */
    float *buffers;        /* [nbuffers] batch-norm running statistics */
    tcb_cc_views p, g;     /* views into params (+ buffers), grads */
} tcb_cc_net;

/* Checks the dimensions: TCB_ERR_INPUT naming the bad one. */
int tcb_cc_dims_check(const tcb_cc_dims *d, const char *where, tcb_error *err);

size_t tcb_cc_param_count(const tcb_cc_dims *d);

/* Allocates a network with zeroed parameters and gradients and PyTorch's
 * initial running statistics (mean 0, variance 1). */
int tcb_cc_net_create(const tcb_cc_dims *d, tcb_cc_net **out, tcb_error *err);
void tcb_cc_net_free(tcb_cc_net *n);

/* The CC code's initialisation (my_utils.weights_init over PyTorch's
 * defaults): conv weights N(0, 0.02) and conv biases U(±1/√fan_in); Linear
 * weights and biases U(±1/√fan_in); batch-norm γ N(1, 0.02), β 0. Drawn in
 * the flat order from rng. */
void tcb_cc_net_init(tcb_cc_net *n, tcb_rng *rng);

void tcb_cc_net_zero_grad(tcb_cc_net *n);

/* Weights and running statistics as raw little-endian float32 (parameters,
 * then buffers) plus a JSON manifest {"format": "tcbench-cc-weights",
 * "version", "C", "Z", "H", "L", "nparams", "nbuffers", "tensors":
 * [{"name", "shape", "offset", "count"}]}, offsets in floats into that
 * file (a buffer's offset is ≥ nparams), names as the CC code's state_dict
 * ("encoder.0.conv1.weight", "decoder.MLP.fc_3.bn0.running_mean"), conv
 * weights written as [out, in]. Both files are written atomically. */
int tcb_cc_net_export(const tcb_cc_net *n, const char *bin_path, const char *manifest_path,
                      tcb_error *err);

/* The manifest export writes (the caller deletes it) and the weights as
 * parts (parameters, buffers) for neural/weights.h. */
cJSON *tcb_cc_net_manifest(const tcb_cc_net *n);
tcb_weight_parts tcb_cc_net_weights(const tcb_cc_net *n);
/* Reads what export wrote into a network of the same dimensions; any
 * mismatch (format, dims, a tensor's name, shape or offset, the file size)
 * is TCB_ERR_INPUT naming the file and key. */
int tcb_cc_net_import(tcb_cc_net *n, const char *bin_path, const char *manifest_path, tcb_error *err);

#endif
