/* Trained weights on disk, shared by the trained methods:
 *
 *  - raw little-endian float32 files (what the PyTorch cross-checks read
 *    with numpy), one or several flat vectors back to back;
 *  - JSON manifests naming each tensor inside them (name, shape, offset),
 *    checked item by item on import so a mismatch names the key;
 *  - the one-file model checkpoint the harness publishes after a fit:
 *        char   magic[8]   the method's, e.g. "TCBATLS1"
 *        uint64 seed       of the fit
 *        uint64 mlen       then the manifest JSON, mlen bytes
 *        float  weights[]  the rest, little-endian float32
 *
 * A weight set is described by parts: `n` flat vectors data[k] of count[k]
 * floats, stored in order (the atlas family has one, its parameters; cc
 * two, its parameters and its batch-norm running statistics). */
#ifndef TCB_NEURAL_WEIGHTS_H
#define TCB_NEURAL_WEIGHTS_H

#include <stddef.h>
#include <stdint.h>

#include <cjson/cJSON.h>

#include "tcb/error.h"

typedef struct tcb_weight_parts {
    int n;
    float *data[2];
    size_t count[2];
} tcb_weight_parts;

/* Writes the parts to path atomically as little-endian float32. */
int tcb_weights_write(const char *path, const tcb_weight_parts *w, tcb_error *err);

/* Reads a file written by tcb_weights_write into the parts; a size other
 * than Σ count is TCB_ERR_INPUT naming the file. */
int tcb_weights_read(const char *path, const tcb_weight_parts *w, tcb_error *err);

/* Appends {"name", "shape", "offset", "count"} to a manifest's tensor array
 * (count = the product of the rank dims in shape). */
void tcb_manifest_add_tensor(cJSON *tensors, const char *name, const int *shape, int rank, size_t offset);

/* got must equal want item by item; else TCB_ERR_INPUT naming `where` and
 * the first key that differs, with the value this model expects. */
int tcb_manifest_check(const cJSON *got, const cJSON *want, const char *where, tcb_error *err);

/* The two-file form the PyTorch cross-checks read: the weights at bin_path,
 * the manifest as JSON at manifest_path, each written atomically. */
int tcb_weights_export(const char *bin_path, const char *manifest_path, const cJSON *manifest,
                       const tcb_weight_parts *w, tcb_error *err);

/* Reads that form into the parts; the manifest must equal `want`. */
int tcb_weights_import(const char *bin_path, const char *manifest_path, const cJSON *want,
                       const tcb_weight_parts *w, tcb_error *err);

/* The one-file model checkpoint: manifest and weights under a magic and the
 * fit's seed, written atomically. */
int tcb_model_file_write(const char *path, const char magic[8], uint64_t seed, const cJSON *manifest,
                         const tcb_weight_parts *w, tcb_error *err);

/* Reads a model file whose manifest must equal `want` (tcb_manifest_check);
 * a bad magic or length, or a weight size that does not fit, is
 * TCB_ERR_INPUT naming the file. On failure the parts may be partly
 * written, *seed is unchanged. */
int tcb_model_file_read(const char *path, const char magic[8], const cJSON *want, uint64_t *seed,
                        const tcb_weight_parts *w, tcb_error *err);

/* The fit's seed alone, for a method whose sizes follow from what the seed
 * rebuilds (PDG's template); a bad magic is TCB_ERR_INPUT naming the file. */
int tcb_model_file_seed(const char *path, const char magic[8], uint64_t *seed, tcb_error *err);

#endif
