#include "methods/cycle/net.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tcb/json.h"

#define MANIFEST_FORMAT "tcbench-cc-weights"
#define MANIFEST_VERSION 1
#define NAME_LEN 64
#define MAX_GROUPS (2 * 8 + 5 + 3 * TCB_CC_MAX_META)

/* ---- the tensor table: every linear map and batch norm, in flat order ---- */

typedef enum kind { LINEAR, CONV, BN } kind;

typedef struct group {
    kind kind;
    char name[NAME_LEN]; /* state_dict prefix */
    int in, out;         /* BN: in = out = C */
    tcb_linear *lin;     /* LINEAR, CONV */
    tcb_batchnorm *bn;   /* BN */
} group;

static void add(group *g, int *n, kind k, int in, int out, tcb_linear *lin, tcb_batchnorm *bn,
                const char *fmt, ...)
{
    group *e = &g[(*n)++];
    e->kind = k, e->in = in, e->out = out, e->lin = lin, e->bn = bn;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(e->name, sizeof e->name, fmt, ap);
    va_end(ap);
}

static int meta_din(const tcb_cc_dims *d, int l) { return l == 0 ? 3 : d->H; }
static int meta_dout(const tcb_cc_dims *d, int l) { return l == d->L ? 3 : d->H; }

/* The groups of dims d with their view slots in v; returns their count. The
 * names follow AE_Meta_AtlasNet's state_dict: encoder = Sequential(
 * PointNetfeat, Linear, BatchNorm1d, ReLU), the decoder's MLP a Sequential
 * of Meta_FC_Layer_2 named fc_0 … fc_{L-1}, fc_end. */
static int list_groups(const tcb_cc_dims *d, tcb_cc_views *v, group *g)
{
    int n = 0;
    for (int e = 0; e < 2; e++) {
        const char *pre = e ? "encoder2" : "encoder";
        tcb_cc_encoder *enc = &v->enc[e];
        add(g, &n, CONV, 3, TCB_CC_ENC1, &enc->conv1, NULL, "%s.0.conv1", pre);
        add(g, &n, BN, TCB_CC_ENC1, TCB_CC_ENC1, NULL, &enc->bn1, "%s.0.bn1", pre);
        add(g, &n, CONV, TCB_CC_ENC1, TCB_CC_ENC2, &enc->conv2, NULL, "%s.0.conv2", pre);
        add(g, &n, BN, TCB_CC_ENC2, TCB_CC_ENC2, NULL, &enc->bn2, "%s.0.bn2", pre);
        add(g, &n, CONV, TCB_CC_ENC2, d->C, &enc->conv3, NULL, "%s.0.conv3", pre);
        add(g, &n, BN, d->C, d->C, NULL, &enc->bn3, "%s.0.bn3", pre);
        add(g, &n, LINEAR, d->C, d->Z, &enc->fc, NULL, "%s.1", pre);
        add(g, &n, BN, d->Z, d->Z, NULL, &enc->bnf, "%s.2", pre);
    }
    tcb_cc_predictor *p = &v->pred;
    int K = (int)(12 + (size_t)d->L * ((size_t)d->H * d->H + d->H));
    add(g, &n, LINEAR, 2 * d->Z, d->Z, &p->fc1, NULL, "decoder.parameter_predictor.fc1");
    add(g, &n, BN, d->Z, d->Z, NULL, &p->bn1, "decoder.parameter_predictor.bn1");
    add(g, &n, LINEAR, d->Z, d->Z / 2, &p->fc2, NULL, "decoder.parameter_predictor.fc2");
    add(g, &n, BN, d->Z / 2, d->Z / 2, NULL, &p->bn2, "decoder.parameter_predictor.bn2");
    add(g, &n, LINEAR, d->Z / 2, K, &p->fc3, NULL, "decoder.parameter_predictor.fc3");
    for (int l = 0; l <= d->L; l++) {
        tcb_cc_meta_layer *m = &v->meta[l];
        int din = meta_din(d, l), dout = meta_dout(d, l);
        char name[16];
        if (l < d->L) snprintf(name, sizeof name, "fc_%d", l);
        else snprintf(name, sizeof name, "fc_end");
        add(g, &n, BN, din, din, NULL, &m->bn0, "decoder.MLP.%s.bn0", name);
        add(g, &n, CONV, din, dout, &m->conv, NULL, "decoder.MLP.%s.fc.conv1", name);
        if (l < d->L) add(g, &n, BN, dout, dout, NULL, &m->bn1, "decoder.MLP.%s.fc.bn1", name);
    }
    return n;
}

static size_t group_params(const group *e)
{
    return e->kind == BN ? 2 * (size_t)e->out : (size_t)e->in * e->out + (size_t)e->out;
}

/* Views v into params (and buffers, when not NULL); also fills the meta
 * layers' dimensions and their slices of the predicted vector. */
static void bind(const tcb_cc_dims *d, float *params, float *buffers, tcb_cc_views *v)
{
    memset(v, 0, sizeof *v);
    group g[MAX_GROUPS];
    int n = list_groups(d, v, g);
    size_t poff = 0, boff = 0;
    for (int k = 0; k < n; k++) {
        if (g[k].kind == BN) tcb_batchnorm_bind(g[k].bn, params, &poff, buffers, &boff, g[k].out);
        else tcb_linear_bind(g[k].lin, params, &poff, g[k].in, g[k].out);
    }
    size_t at = 0;
    for (int l = 0; l <= d->L; l++) {
        tcb_cc_meta_layer *m = &v->meta[l];
        m->din = meta_din(d, l), m->dout = meta_dout(d, l);
        m->w_at = at, m->b_at = at + (size_t)m->din * m->din;
        at = m->b_at + (size_t)m->din;
    }
}

int tcb_cc_dims_check(const tcb_cc_dims *d, const char *where, tcb_error *err)
{
    if (d->C < 1 || d->C > 65536)
        return tcb_fail(err, TCB_ERR_INPUT, "%s: encoder width C %d outside 1..65536", where, d->C);
    if (d->Z < 2 || d->Z > 65536 || d->Z % 2)
        return tcb_fail(err, TCB_ERR_INPUT, "%s: latent size Z %d must be even, 2..65536", where, d->Z);
    if (d->H < 1 || d->H > 4096)
        return tcb_fail(err, TCB_ERR_INPUT, "%s: meta-MLP width H %d outside 1..4096", where, d->H);
    if (d->L < 1 || d->L + 1 > TCB_CC_MAX_META)
        return tcb_fail(err, TCB_ERR_INPUT, "%s: meta-MLP hidden layers L %d outside 1..%d", where, d->L,
                        TCB_CC_MAX_META - 1);
    if (d->residual != 0 && d->residual != 1)
        return tcb_fail(err, TCB_ERR_INPUT, "%s: residual %d is neither 0 nor 1", where, d->residual);
    return TCB_OK;
}

size_t tcb_cc_param_count(const tcb_cc_dims *d)
{
    tcb_cc_views v;
    group g[MAX_GROUPS];
    int n = list_groups(d, &v, g);
    size_t total = 0;
    for (int k = 0; k < n; k++) total += group_params(&g[k]);
    return total;
}

static size_t buffer_count(const tcb_cc_dims *d)
{
    tcb_cc_views v;
    group g[MAX_GROUPS];
    int n = list_groups(d, &v, g);
    size_t total = 0;
    for (int k = 0; k < n; k++)
        if (g[k].kind == BN) total += 2 * (size_t)g[k].out;
    return total;
}

int tcb_cc_net_create(const tcb_cc_dims *d, tcb_cc_net **out, tcb_error *err)
{
    *out = NULL;
    int rc = tcb_cc_dims_check(d, "cc network", err);
    if (rc) return rc;
    tcb_cc_net *n = calloc(1, sizeof *n);
    if (!n) return tcb_fail(err, TCB_ERR_NOMEM, "cc network: out of memory");
    n->d = *d, n->n_meta = d->L + 1;
    n->K = 12 + (size_t)d->L * ((size_t)d->H * d->H + d->H);
    n->nparams = tcb_cc_param_count(d), n->nbuffers = buffer_count(d);
    n->params = calloc(n->nparams, sizeof(float));
    n->grads = calloc(n->nparams, sizeof(float));
    n->buffers = calloc(n->nbuffers, sizeof(float));
    if (!n->params || !n->grads || !n->buffers) {
        tcb_cc_net_free(n);
        return tcb_fail(err, TCB_ERR_NOMEM, "cc network: out of memory for %zu parameters", tcb_cc_param_count(d));
    }
    bind(d, n->params, n->buffers, &n->p);
    bind(d, n->grads, NULL, &n->g);
    tcb_cc_views v;
    group g[MAX_GROUPS];
    int ng = list_groups(d, &v, g);
    /* the running statistics start as PyTorch's: mean 0, variance 1 */
    bind(d, n->params, n->buffers, &v);
    for (int k = 0; k < ng; k++)
        if (g[k].kind == BN) tcb_batchnorm_reset_running(g[k].bn);
    *out = n;
    return TCB_OK;
}

void tcb_cc_net_free(tcb_cc_net *n)
{
    if (!n) return;
    free(n->params), free(n->grads), free(n->buffers);
    free(n);
}

static float uniform(tcb_rng *rng, double bound) { return (float)((2.0 * tcb_rng_uniform(rng) - 1.0) * bound); }

void tcb_cc_net_init(tcb_cc_net *n, tcb_rng *rng)
{
    tcb_cc_views v;
    group g[MAX_GROUPS];
    int ng = list_groups(&n->d, &v, g);
    bind(&n->d, n->params, n->buffers, &v);
    for (int k = 0; k < ng; k++) {
        const group *e = &g[k];
        if (e->kind == BN) {
            for (int c = 0; c < e->out; c++) e->bn->gamma[c] = (float)(1.0 + 0.02 * tcb_rng_normal(rng));
            memset(e->bn->beta, 0, (size_t)e->out * sizeof(float));
            continue;
        }
        double bound = 1.0 / sqrt((double)e->in);
        size_t nw = (size_t)e->in * e->out;
        for (size_t i = 0; i < nw; i++)
            e->lin->W[i] = e->kind == CONV ? (float)(0.02 * tcb_rng_normal(rng)) : uniform(rng, bound);
        for (int i = 0; i < e->out; i++) e->lin->b[i] = uniform(rng, bound);
    }
}

void tcb_cc_net_zero_grad(tcb_cc_net *n) { memset(n->grads, 0, n->nparams * sizeof(float)); }

/* ---- export / import ---- */

static void add_tensor(cJSON *tensors, const char *prefix, const char *suffix, const int *shape, int rank,
                       size_t *off)
{
    char name[NAME_LEN + 16];
    snprintf(name, sizeof name, "%s.%s", prefix, suffix);
    tcb_manifest_add_tensor(tensors, name, shape, rank, *off);
    size_t count = 1;
    for (int k = 0; k < rank; k++) count *= (size_t)shape[k];
    *off += count;
}

cJSON *tcb_cc_net_manifest(const tcb_cc_net *n)
{
    cJSON *root = cJSON_CreateObject(), *tensors = cJSON_CreateArray();
    cJSON_AddStringToObject(root, "format", MANIFEST_FORMAT);
    cJSON_AddNumberToObject(root, "version", MANIFEST_VERSION);
    cJSON_AddNumberToObject(root, "C", n->d.C);
    cJSON_AddNumberToObject(root, "Z", n->d.Z);
    cJSON_AddNumberToObject(root, "H", n->d.H);
    cJSON_AddNumberToObject(root, "L", n->d.L);
    cJSON_AddBoolToObject(root, "residual", n->d.residual);
    cJSON_AddNumberToObject(root, "nparams", (double)n->nparams);
    cJSON_AddNumberToObject(root, "nbuffers", (double)n->nbuffers);
    cJSON_AddItemToObject(root, "tensors", tensors);
    tcb_cc_views v;
    group g[MAX_GROUPS];
    int ng = list_groups(&n->d, &v, g);
    size_t off = 0;
    for (int k = 0; k < ng; k++) {
        int shape[2] = {g[k].out, g[k].in};
        add_tensor(tensors, g[k].name, "weight", g[k].kind == BN ? shape + 1 : shape, g[k].kind == BN ? 1 : 2,
                   &off);
        add_tensor(tensors, g[k].name, "bias", shape, 1, &off);
    }
    for (int k = 0; k < ng; k++)
        if (g[k].kind == BN) {
            add_tensor(tensors, g[k].name, "running_mean", &g[k].out, 1, &off);
            add_tensor(tensors, g[k].name, "running_var", &g[k].out, 1, &off);
        }
    return root;
}

tcb_weight_parts tcb_cc_net_weights(const tcb_cc_net *n)
{
    return (tcb_weight_parts){.n = 2, .data = {n->params, n->buffers}, .count = {n->nparams, n->nbuffers}};
}

int tcb_cc_net_export(const tcb_cc_net *n, const char *bin_path, const char *manifest_path, tcb_error *err)
{
    cJSON *manifest = tcb_cc_net_manifest(n);
    tcb_weight_parts w = tcb_cc_net_weights(n);
    int rc = tcb_weights_export(bin_path, manifest_path, manifest, &w, err);
    cJSON_Delete(manifest);
    return rc;
}

int tcb_cc_net_import(tcb_cc_net *n, const char *bin_path, const char *manifest_path, tcb_error *err)
{
    cJSON *want = tcb_cc_net_manifest(n);
    tcb_weight_parts w = tcb_cc_net_weights(n);
    int rc = tcb_weights_import(bin_path, manifest_path, want, &w, err);
    cJSON_Delete(want);
    return rc;
}
