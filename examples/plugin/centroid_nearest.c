/* centroid_nearest — a complete out-of-tree tcbench method, the template of
 * docs/adding-a-method.md.
 *
 * The idea: `nearest` fails as soon as the shape translates between frames.
 * Remove the translation first: shift the points of frame i by the
 * difference of the two frames' point-pool centroids, then let the harness
 * project them onto frame j's vertices. One parameter, "translate"
 * (default true), switches the shift off (then it equals `nearest`).
 *
 * Build against the installed headers:
 *     cc -std=c11 -O2 -shared -fPIC -I<prefix>/include centroid_nearest.c \
 *        -L<prefix>/lib -ltcbench -lcjson -o libcentroid_nearest.so
 * Run:
 *     tcbench --plugin ./libcentroid_nearest.so run my-config.json */
#include <stdlib.h>
#include <string.h>

#include <cjson/cJSON.h>
#include <tcb/method.h>

typedef struct model {
    int translate;
    int n_frames;
    double (*centroid)[3]; /* [n_frames][3], computed in fit */
} model;

static int cn_create(const char *params_json, void **self, tcb_error *err)
{
    cJSON *params = cJSON_Parse(params_json && *params_json ? params_json : "{}");
    if (!cJSON_IsObject(params)) {
        cJSON_Delete(params);
        return tcb_fail(err, TCB_ERR_INPUT, "centroid_nearest.params: expected a JSON object");
    }
    model *m = calloc(1, sizeof *m);
    if (!m) {
        cJSON_Delete(params);
        return tcb_fail(err, TCB_ERR_NOMEM, "centroid_nearest: out of memory");
    }
    m->translate = 1;
    for (const cJSON *item = params->child; item; item = item->next) {
        if (strcmp(item->string, "translate") != 0 || !cJSON_IsBool(item)) {
            int rc = tcb_fail(err, TCB_ERR_INPUT, "centroid_nearest.params.%s: unknown key or not a boolean",
                              item->string);
            cJSON_Delete(params);
            free(m);
            return rc;
        }
        m->translate = cJSON_IsTrue(item);
    }
    cJSON_Delete(params);
    *self = m;
    return TCB_OK;
}

/* The centroid of each frame's surface samples: only the point pools are
 * used, never the correspondence of vertex ids. */
static int cn_fit(void *self, const tcb_sequence *seq, const tcb_fit_ctx *ctx, tcb_error *err)
{
    model *m = self;
    m->n_frames = seq->n_frames;
    m->centroid = calloc((size_t)seq->n_frames, sizeof *m->centroid);
    if (!m->centroid) return tcb_fail(err, TCB_ERR_NOMEM, "centroid_nearest: out of memory");
    for (int f = 0; f < seq->n_frames; f++) {
        const float *pool = tcb_seq_pool(seq, f);
        for (int p = 0; p < seq->pool_size; p++)
            for (int d = 0; d < 3; d++) m->centroid[f][d] += pool[3 * p + d] / (double)seq->pool_size;
        tcb_report_progress(&ctx->reporter, f + 1, seq->n_frames, "centroid_nearest: centroids");
    }
    return TCB_OK;
}

static int cn_transfer(void *self, const tcb_sequence *seq, int i, int j, const float *src, int n, float *out,
                       tcb_rng *rng, tcb_error *err)
{
    (void)seq, (void)rng, (void)err;
    const model *m = self;
    for (int k = 0; k < n; k++)
        for (int d = 0; d < 3; d++)
            out[3 * k + d] = src[3 * k + d] +
                             (m->translate ? (float)(m->centroid[j][d] - m->centroid[i][d]) : 0.0f);
    return TCB_OK;
}

static void cn_destroy(void *self)
{
    model *m = self;
    if (m) free(m->centroid);
    free(m);
}

static const tcb_method_ops centroid_nearest = {
    .abi_version = TCB_METHOD_ABI_VERSION,
    .name = "centroid_nearest",
    .version = "1.0", /* recorded in every cell it computes */
    .description = "nearest vertex after removing the frames' translation (example plug-in)",
    .create = cn_create,
    .fit = cn_fit,
    .transfer = cn_transfer,
    .destroy = cn_destroy,
};

const tcb_method_ops *const *tcb_plugin_methods(int *count);

const tcb_method_ops *const *tcb_plugin_methods(int *count)
{
    static const tcb_method_ops *const tables[] = {&centroid_nearest};
    *count = 1;
    return tables;
}
