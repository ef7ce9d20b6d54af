#include "methods/atlas/model.h"

#include <math.h>
#include <omp.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tcb/json.h"

#define MANIFEST_FORMAT "tcbench-atlas-weights"
#define MANIFEST_VERSION 1
#define NAME_LEN 64

/* ---- the layer table: layer k < 5 is the encoder's, then 4 per decoder ---- */

static int layer_count(int P) { return TCB_ATLAS_ENC_LAYERS + P * TCB_ATLAS_DEC_LAYERS; }

/* Name prefix (state_dict style) and widths of layer k. */
static void layer_info(int C, int k, char *name, int *in, int *out)
{
    static const char *const enc_names[TCB_ATLAS_ENC_LAYERS] = {"conv1", "conv2", "conv3",
                                                                "fc1", "fc2"};
    if (k < TCB_ATLAS_ENC_LAYERS) {
        snprintf(name, NAME_LEN, "encoder.%s", enc_names[k]);
        tcb_atlas_encoder_dims(C, k, in, out);
        return;
    }
    int p = (k - TCB_ATLAS_ENC_LAYERS) / TCB_ATLAS_DEC_LAYERS;
    int j = (k - TCB_ATLAS_ENC_LAYERS) % TCB_ATLAS_DEC_LAYERS;
    snprintf(name, NAME_LEN, "decoders.%d.fc%d", p, j + 1);
    tcb_atlas_decoder_dims(C, j, in, out);
}

static tcb_linear *layer_view(tcb_atlas_encoder *enc, tcb_atlas_decoder *dec, int k)
{
    if (k < TCB_ATLAS_ENC_LAYERS) return &enc->l[k];
    k -= TCB_ATLAS_ENC_LAYERS;
    return &dec[k / TCB_ATLAS_DEC_LAYERS].l[k % TCB_ATLAS_DEC_LAYERS];
}

static size_t bind(int C, int P, float *base, tcb_atlas_encoder *enc, tcb_atlas_decoder *dec)
{
    size_t off = 0;
    for (int k = 0; k < layer_count(P); k++) {
        char name[NAME_LEN];
        int in, out;
        layer_info(C, k, name, &in, &out);
        tcb_linear_bind(layer_view(enc, dec, k), base, &off, in, out);
    }
    return off;
}

size_t tcb_atlas_param_count(int C, int P)
{
    size_t n = 0;
    for (int k = 0; k < layer_count(P); k++) {
        char name[NAME_LEN];
        int in, out;
        layer_info(C, k, name, &in, &out);
        n += (size_t)in * out + out;
    }
    return n;
}

/* ---- model ---- */

int tcb_atlas_model_create(int C, int P, tcb_atlas_model **out, tcb_error *err)
{
    *out = NULL;
    if (C < 4 || P < 1)
        return tcb_fail(err, TCB_ERR_INPUT, "atlas model: need C >= 4 and P >= 1, got C=%d P=%d",
                        C, P);
    tcb_atlas_model *m = calloc(1, sizeof *m);
    if (!m) return tcb_fail(err, TCB_ERR_NOMEM, "atlas model: out of memory");
    m->C = C, m->P = P;
    m->nparams = tcb_atlas_param_count(C, P);
    m->params = calloc(m->nparams, sizeof(float));
    m->grads = calloc(m->nparams, sizeof(float));
    m->dec = calloc((size_t)P, sizeof *m->dec);
    m->gdec = calloc((size_t)P, sizeof *m->gdec);
    if (!m->params || !m->grads || !m->dec || !m->gdec) {
        tcb_atlas_model_free(m);
        return tcb_fail(err, TCB_ERR_NOMEM, "atlas model: out of memory for %zu parameters",
                        tcb_atlas_param_count(C, P));
    }
    bind(C, P, m->params, &m->enc, m->dec);
    bind(C, P, m->grads, &m->genc, m->gdec);
    *out = m;
    return TCB_OK;
}

void tcb_atlas_model_free(tcb_atlas_model *m)
{
    if (!m) return;
    free(m->params), free(m->grads), free(m->dec), free(m->gdec);
    free(m);
}

void tcb_atlas_model_init(tcb_atlas_model *m, tcb_rng *rng)
{
    for (int k = 0; k < layer_count(m->P); k++) {
        tcb_linear_init_uniform(layer_view(&m->enc, m->dec, k), rng);
    }
}

void tcb_atlas_model_zero_grad(tcb_atlas_model *m)
{
    memset(m->grads, 0, m->nparams * sizeof(float));
}

/* ---- workspace ---- */

int tcb_atlas_work_create(const tcb_atlas_model *m, int B, int N, int M, tcb_atlas_work **out,
                          tcb_error *err)
{
    *out = NULL;
    if (B < 1 || N < 1 || M < m->P || M % m->P)
        return tcb_fail(err, TCB_ERR_INPUT,
                        "atlas workspace: need B, N >= 1 and M a positive multiple of P=%d, "
                        "got B=%d N=%d M=%d", m->P, B, N, M);
    tcb_atlas_work *w = calloc(1, sizeof *w);
    if (!w) return tcb_fail(err, TCB_ERR_NOMEM, "atlas workspace: out of memory");
    w->B = B, w->N = N, w->M = M, w->P = m->P, w->m = M / m->P;
    w->nthreads = omp_get_max_threads() < m->P ? omp_get_max_threads() : m->P;
    size_t stack = (size_t)3 * B * w->m * 3, codes = (size_t)B * m->C;
    int rc;
    w->uv = malloc((size_t)M * 2 * sizeof(float));
    w->dec = calloc((size_t)m->P, sizeof *w->dec);
    w->scratch = calloc((size_t)w->nthreads, sizeof *w->scratch);
    w->out = malloc(m->P * stack * sizeof(float));
    w->dzp = malloc(m->P * codes * sizeof(float));
    w->dz = malloc(codes * sizeof(float));
    if (!w->uv || !w->dec || !w->scratch || !w->out || !w->dzp || !w->dz) {
        rc = tcb_fail(err, TCB_ERR_NOMEM, "atlas workspace: out of memory");
        goto fail;
    }
    if ((rc = tcb_atlas_encoder_cache_alloc(&w->enc, B, N, m->C, err))) goto fail;
    for (int t = 0; t < w->nthreads; t++)
        if ((rc = tcb_atlas_decoder_scratch_alloc(&w->scratch[t], B, w->m, m->C, err))) goto fail;
    for (int p = 0; p < m->P; p++)
        if ((rc = tcb_atlas_decoder_cache_alloc(&w->dec[p], B, w->m, m->C, err))) goto fail;
    *out = w;
    return TCB_OK;
fail:
    tcb_atlas_work_free(w);
    return rc;
}

void tcb_atlas_work_free(tcb_atlas_work *w)
{
    if (!w) return;
    tcb_atlas_encoder_cache_free(&w->enc);
    for (int t = 0; w->scratch && t < w->nthreads; t++)
        tcb_atlas_decoder_scratch_free(&w->scratch[t]);
    for (int p = 0; w->dec && p < w->P; p++) tcb_atlas_decoder_cache_free(&w->dec[p]);
    free(w->uv), free(w->dec), free(w->scratch), free(w->out), free(w->dzp), free(w->dz);
    free(w);
}

/* ---- forward / backward ---- */

/* Patch p's stacked rows [k][b][i] ↔ the arrays [b][p·m + i][3], k = 0, 1, 2
 * for φ, φ_u, φ_v: one run of m·3 floats per (k, b). */
static size_t run_offset(const tcb_atlas_work *w, int p, int b)
{
    return ((size_t)b * w->M + (size_t)p * w->m) * 3;
}

/* stack → arrays */
static void patch_scatter(const tcb_atlas_work *w, int p, int nk, const float *stack,
                          float *const arr[3])
{
    size_t run = (size_t)w->m * 3;
    for (int k = 0; k < nk; k++)
        for (int b = 0; b < w->B; b++)
            memcpy(arr[k] + run_offset(w, p, b), stack + ((size_t)k * w->B + b) * run,
                   run * sizeof(float));
}

/* arrays → stack; a NULL array reads as zeros */
static void patch_gather(const tcb_atlas_work *w, int p, int nk, float *stack,
                         const float *const arr[3])
{
    size_t run = (size_t)w->m * 3;
    for (int k = 0; k < nk; k++)
        for (int b = 0; b < w->B; b++) {
            float *to = stack + ((size_t)k * w->B + b) * run;
            if (arr[k]) memcpy(to, arr[k] + run_offset(w, p, b), run * sizeof(float));
            else memset(to, 0, run * sizeof(float));
        }
}

static float *patch_out(const tcb_atlas_work *w, int p)
{
    return w->out + (size_t)p * 3 * w->B * w->m * 3;
}

void tcb_atlas_model_forward(const tcb_atlas_model *m, tcb_atlas_work *w, const float *clouds,
                             const float *uv, float *phi, float *phi_u, float *phi_v)
{
    float *const arr[3] = {phi, phi_u, phi_v};
    w->nt = phi_u ? 2 : 0;
    memcpy(w->uv, uv, (size_t)w->M * 2 * sizeof(float));
    tcb_atlas_encoder_forward(&m->enc, &w->enc, clouds);
#pragma omp parallel for schedule(static) num_threads(w->nthreads)
    for (int p = 0; p < m->P; p++) {
        tcb_atlas_decoder_forward(&m->dec[p], &w->dec[p], w->enc.z, w->uv + (size_t)2 * p * w->m,
                                  w->nt, patch_out(w, p));
        patch_scatter(w, p, 1 + w->nt, patch_out(w, p), arr);
    }
}

int tcb_atlas_model_backward(tcb_atlas_model *m, tcb_atlas_work *w, const float *dphi,
                             const float *dphi_u, const float *dphi_v, tcb_error *err)
{
    const float *const arr[3] = {dphi, dphi_u, dphi_v};
    int nt = dphi_u || dphi_v ? 2 : 0;
    size_t codes = (size_t)w->B * m->C;
    if (nt > w->nt)
        return tcb_fail(err, TCB_ERR_INTERNAL,
                        "atlas backward: tangent gradients given but the forward had no tangents");
    memset(w->dzp, 0, m->P * codes * sizeof(float));
#pragma omp parallel for schedule(static) num_threads(w->nthreads)
    for (int p = 0; p < m->P; p++) {
        patch_gather(w, p, 1 + nt, patch_out(w, p), arr);
        tcb_atlas_decoder_backward(&m->dec[p], &m->gdec[p], &w->dec[p],
                                   &w->scratch[omp_get_thread_num()], w->enc.z,
                                   w->uv + (size_t)2 * p * w->m, patch_out(w, p), nt,
                                   w->dzp + p * codes, NULL);
    }
    /* the patches' latent gradients, summed in patch order */
    memcpy(w->dz, w->dzp, codes * sizeof(float));
    for (int p = 1; p < m->P; p++)
        for (size_t i = 0; i < codes; i++) w->dz[i] += w->dzp[p * codes + i];
    tcb_atlas_encoder_backward(&m->enc, &m->genc, &w->enc, w->dz);
    return TCB_OK;
}

/* ---- export / import ---- */

cJSON *tcb_atlas_model_manifest(const tcb_atlas_model *m)
{
    cJSON *root = cJSON_CreateObject(), *tensors = cJSON_CreateArray();
    cJSON_AddStringToObject(root, "format", MANIFEST_FORMAT);
    cJSON_AddNumberToObject(root, "version", MANIFEST_VERSION);
    cJSON_AddNumberToObject(root, "C", m->C);
    cJSON_AddNumberToObject(root, "P", m->P);
    cJSON_AddNumberToObject(root, "nparams", (double)m->nparams);
    cJSON_AddItemToObject(root, "tensors", tensors);
    size_t off = 0;
    for (int k = 0; k < layer_count(m->P); k++) {
        char prefix[NAME_LEN], name[NAME_LEN + 8];
        int in, out;
        layer_info(m->C, k, prefix, &in, &out);
        int shape[2] = {out, in};
        snprintf(name, sizeof name, "%s.weight", prefix);
        tcb_manifest_add_tensor(tensors, name, shape, 2, off);
        off += (size_t)in * out;
        snprintf(name, sizeof name, "%s.bias", prefix);
        tcb_manifest_add_tensor(tensors, name, shape, 1, off);
        off += (size_t)out;
    }
    return root;
}

tcb_weight_parts tcb_atlas_model_weights(const tcb_atlas_model *m)
{
    return (tcb_weight_parts){.n = 1, .data = {m->params}, .count = {m->nparams}};
}

int tcb_atlas_model_export(const tcb_atlas_model *m, const char *bin_path, const char *manifest_path, tcb_error *err)
{
    cJSON *manifest = tcb_atlas_model_manifest(m);
    tcb_weight_parts w = tcb_atlas_model_weights(m);
    int rc = tcb_weights_export(bin_path, manifest_path, manifest, &w, err);
    cJSON_Delete(manifest);
    return rc;
}

int tcb_atlas_model_import(tcb_atlas_model *m, const char *bin_path, const char *manifest_path, tcb_error *err)
{
    cJSON *want = tcb_atlas_model_manifest(m);
    tcb_weight_parts w = tcb_atlas_model_weights(m);
    int rc = tcb_weights_import(bin_path, manifest_path, want, &w, err);
    cJSON_Delete(want);
    return rc;
}
