/* The atlas network (reference-protocol §2): a PointNet encoder and P patch
 * decoders, shared by AtlasNet, DSR and MCA, which differ only in the loss.
 *
 * All parameters live in ONE contiguous float vector (and their gradients in
 * a second one of the same layout), so the optimizer and checkpoints treat
 * them as flat vectors; the encoder and decoder structs are named views into
 * them. Tensor order: encoder conv1, conv2, conv3, fc1, fc2, then decoders
 * 0..P-1 each fc1..fc4; per layer the weight [out][in] then the bias [out]. */
#ifndef TCB_ATLAS_MODEL_H
#define TCB_ATLAS_MODEL_H

#include <stddef.h>

#include "methods/atlas/decoder.h"
#include "methods/atlas/encoder.h"
#include "neural/weights.h"
#include "tcb/error.h"
#include "tcb/rng.h"

typedef struct tcb_atlas_model {
    int C, P;           /* latent size, number of patches */
    size_t nparams;
    float *params;      /* [nparams] */
    float *grads;       /* [nparams] */
    tcb_atlas_encoder enc, genc;   /* views into params, grads */
    tcb_atlas_decoder *dec, *gdec; /* [P] views into params, grads */
} tcb_atlas_model;

/* Number of parameters: 19,368,952 at C = 1024, P = 10 (reference-protocol
 * §2.2: 2,239,872 encoder + 10 × 1,712,908). */
size_t tcb_atlas_param_count(int C, int P);

/* Allocates a model with zeroed parameters and gradients. */
int tcb_atlas_model_create(int C, int P, tcb_atlas_model **out, tcb_error *err);
void tcb_atlas_model_free(tcb_atlas_model *m);

/* PyTorch's default init for Linear and Conv1d: weights and biases
 * U(−1/√fan_in, 1/√fan_in), drawn in the flat order from rng. */
void tcb_atlas_model_init(tcb_atlas_model *m, tcb_rng *rng);

void tcb_atlas_model_zero_grad(tcb_atlas_model *m);

/* Everything one training step needs besides the parameters, for B shapes
 * of N input points and M UV samples (patch p decodes samples
 * [p·M/P, (p+1)·M/P), as reference-protocol §2.3); M must be a multiple of P.
 * Allocated once and reused: a step allocates nothing.
 *
 * Threading: the encoder's large GEMMs use OpenBLAS's threads; the decoders
 * run patch-parallel, one patch per thread with single-threaded GEMMs (OpenBLAS
 * sees it is inside a parallel region): at the CPU scale the per-patch GEMMs
 * are too small to split well. Results are bitwise reproducible for a given
 * thread count; across thread counts only the last bits move (OpenBLAS tiles
 * a threaded GEMM's edges differently). nthreads = min(P, the OpenMP thread
 * count at creation). */
typedef struct tcb_atlas_work {
    int B, N, M, P, m; /* m = M / P samples per patch */
    int nt;            /* tangents in the last forward: 0 or 2 */
    int nthreads;
    float *uv;                            /* [M][2] the forward's samples */
    tcb_atlas_encoder_cache enc;          /* enc.z [B][C]: the latent codes */
    tcb_atlas_decoder_cache *dec;         /* [P] */
    tcb_atlas_decoder_scratch *scratch;   /* [nthreads] */
    float *out;                           /* [P][3·B·m][3] each patch's stacked output */
    float *dzp;                           /* [P][B][C] each patch's ∂L/∂z */
    float *dz;                            /* [B][C] their sum, in patch order */
} tcb_atlas_work;

int tcb_atlas_work_create(const tcb_atlas_model *m, int B, int N, int M,
                          tcb_atlas_work **out, tcb_error *err);
void tcb_atlas_work_free(tcb_atlas_work *w);

/* clouds [B][N][3], uv [M][2] (shared by the B shapes) → phi [B][M][3] and,
 * when phi_u and phi_v are not NULL (both or neither), the Jacobian columns
 * phi_u = ∂φ/∂u, phi_v = ∂φ/∂v [B][M][3]. Without them no tangent is
 * propagated (a third of the work). */
void tcb_atlas_model_forward(const tcb_atlas_model *m, tcb_atlas_work *w, const float *clouds,
                             const float *uv, float *phi, float *phi_u, float *phi_v);

/* m->grads += ∂L/∂params from the upstream gradients dphi, dphi_u, dphi_v
 * [B][M][3] of the last forward (NULL = zero; with both tangent gradients
 * NULL the tangent rows are skipped). Consumes the forward's caches: one
 * backward per forward. A tangent gradient after a forward without tangents
 * is TCB_ERR_INTERNAL. */
int tcb_atlas_model_backward(tcb_atlas_model *m, tcb_atlas_work *w, const float *dphi,
                             const float *dphi_u, const float *dphi_v, tcb_error *err);

/* Weights as raw little-endian float32 (the flat vector) plus a JSON
 * manifest {"format", "version", "C", "P", "nparams", "tensors": [{"name",
 * "shape", "offset", "count"}]}, offsets in floats; tensor names follow
 * PyTorch's state_dict ("encoder.conv1.weight", "decoders.3.fc2.bias"), conv
 * weights written as [out, in]. Both files are written atomically. */
int tcb_atlas_model_export(const tcb_atlas_model *m, const char *bin_path,
                           const char *manifest_path, tcb_error *err);

/* The manifest export writes (the caller deletes it) and the weights as
 * parts (one: the flat parameter vector), for neural/weights.h. */
cJSON *tcb_atlas_model_manifest(const tcb_atlas_model *m);
tcb_weight_parts tcb_atlas_model_weights(const tcb_atlas_model *m);

/* Reads weights written by export into a model of the same C and P; any
 * mismatch of the manifest (format, dims, a tensor's name, shape or offset)
 * or of the file size is TCB_ERR_INPUT naming the file and key. */
int tcb_atlas_model_import(tcb_atlas_model *m, const char *bin_path, const char *manifest_path,
                           tcb_error *err);

#endif
