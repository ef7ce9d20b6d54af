/* Test-only methods for the runner's integration tests, built by the test
 * scripts into a plug-in. Not a benchmark method: each exists to drive one
 * code path of the harness.
 *
 *   slow_noisy  oracle plus seeded noise, with a checkpoint (save/load), a
 *               reconstruction and an optional sleep per pair (delay_ms), so
 *               a test can kill a run while cells are being evaluated; with
 *               resumed_fit_s its fit says it continued a training that had
 *               cost that many seconds before
 *   faulty      fails on purpose: "mode" = "fit" (an error in fit),
 *               "numeric" (TCB_ERR_NUMERIC from transfer at pair `at`),
 *               "nan" (a NaN point from transfer at pair `at`), "huge"
 *               (one finite point at 1e30), "ids" (vertex ids written as
 *               the x coordinate, from pair `at` on): a plug-in's bugs
 *   thread_probe  identity transfer that fails unless it runs with the
 *               OpenMP thread count its fit was given (ctx->n_threads):
 *               the cell's thread budget covers the evaluation too */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <cjson/cJSON.h>
#include <tcb/method.h>

typedef struct model {
    int delay_ms;
    double noise;
    double offset;   /* drawn in fit from the seed: checks save/load round trips */
    int mode;        /* faulty: 0 fit, 1 numeric, 2 nan, 3 huge, 4 ids */
    int at;          /* faulty: the failing transfer call */
    double resumed_fit_s; /* slow_noisy: reported through ctx->resumed_fit_s */
    int calls;
    int fit_threads; /* thread_probe: ctx->n_threads of the fit */
} model;

static int parse(const char *params_json, const char *name, model *m, tcb_error *err)
{
    cJSON *p = cJSON_Parse(params_json && *params_json ? params_json : "{}");
    if (!cJSON_IsObject(p)) {
        cJSON_Delete(p);
        return tcb_fail(err, TCB_ERR_INPUT, "%s.params: expected an object", name);
    }
    int rc = TCB_OK;
    for (const cJSON *it = p->child; it && !rc; it = it->next) {
        if (strcmp(it->string, "delay_ms") == 0 && cJSON_IsNumber(it)) m->delay_ms = it->valueint;
        else if (strcmp(it->string, "noise") == 0 && cJSON_IsNumber(it)) m->noise = it->valuedouble;
        else if (strcmp(it->string, "at") == 0 && cJSON_IsNumber(it)) m->at = it->valueint;
        else if (strcmp(it->string, "resumed_fit_s") == 0 && cJSON_IsNumber(it))
            m->resumed_fit_s = it->valuedouble;
        else if (strcmp(it->string, "mode") == 0 && cJSON_IsString(it)) {
            const char *modes[] = {"fit", "numeric", "nan", "huge", "ids"};
            m->mode = -1;
            for (int k = 0; k < (int)(sizeof modes / sizeof modes[0]); k++)
                if (strcmp(it->valuestring, modes[k]) == 0) m->mode = k;
            if (m->mode < 0)
                rc = tcb_fail(err, TCB_ERR_INPUT, "%s.params.mode: unknown mode '%s'", name,
                              it->valuestring);
        } else {
            rc = tcb_fail(err, TCB_ERR_INPUT, "%s.params.%s: unknown key", name, it->string);
        }
    }
    cJSON_Delete(p);
    return rc;
}

static int create_as(const char *name, const char *params_json, void **self, tcb_error *err)
{
    model *m = calloc(1, sizeof *m);
    if (!m) return tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", name);
    int rc = parse(params_json, name, m, err);
    if (rc) {
        free(m);
        return rc;
    }
    *self = m;
    return TCB_OK;
}

static int sn_create(const char *params_json, void **self, tcb_error *err)
{
    return create_as("slow_noisy", params_json, self, err);
}

static int fy_create(const char *params_json, void **self, tcb_error *err)
{
    return create_as("faulty", params_json, self, err);
}

static int sn_fit(void *self, const tcb_sequence *seq, const tcb_fit_ctx *ctx, tcb_error *err)
{
    (void)seq, (void)err;
    model *m = self;
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, ctx->seed, "slow_noisy/fit");
    m->offset = 1e-3 * tcb_rng_uniform(&rng);
    if (ctx->resumed_fit_s) *ctx->resumed_fit_s = m->resumed_fit_s;
    tcb_report_progress(&ctx->reporter, 1, 1, "slow_noisy: fit");
    return TCB_OK;
}

/* %a: the offset must come back bit for bit, or resumed cells would differ. */
static int sn_save(void *self, const char *path, tcb_error *err)
{
    FILE *f = fopen(path, "w");
    if (!f) return tcb_fail(err, TCB_ERR_IO, "%s: cannot write", path);
    fprintf(f, "%a\n", ((model *)self)->offset);
    return fclose(f) == 0 ? TCB_OK : tcb_fail(err, TCB_ERR_IO, "%s: cannot write", path);
}

static int sn_load(void *self, const tcb_sequence *seq, const char *path, tcb_error *err)
{
    (void)seq;
    FILE *f = fopen(path, "r");
    if (!f) return tcb_fail(err, TCB_ERR_IO, "%s: cannot read", path);
    int ok = fscanf(f, "%la", &((model *)self)->offset) == 1;
    fclose(f);
    return ok ? TCB_OK : tcb_fail(err, TCB_ERR_INPUT, "%s: not a checkpoint", path);
}

static int sn_transfer(void *self, const tcb_sequence *seq, int i, int j, const float *src, int n,
                       float *out, tcb_rng *rng, tcb_error *err)
{
    (void)i, (void)src, (void)err;
    const model *m = self;
    if (m->delay_ms > 0) {
        struct timespec ts = {m->delay_ms / 1000, (long)(m->delay_ms % 1000) * 1000000L};
        nanosleep(&ts, NULL);
    }
    const float *vj = tcb_seq_frame(seq, j);
    for (int k = 0; k < 3 * n; k++)
        out[k] = vj[k] + (float)(m->offset + m->noise * tcb_rng_normal(rng));
    return TCB_OK;
}

static int sn_reconstruct(void *self, const tcb_sequence *seq, int i, int j, int frame,
                          tcb_rng *rng, float **pts, int *n, tcb_error *err)
{
    (void)self, (void)i, (void)j;
    *n = 64;
    *pts = malloc(64 * 3 * sizeof(float));
    if (!*pts) return tcb_fail(err, TCB_ERR_NOMEM, "slow_noisy: out of memory");
    return tcb_sequence_draw_points(seq, frame, 64, 1, rng, *pts, err);
}

static int fy_fit(void *self, const tcb_sequence *seq, const tcb_fit_ctx *ctx, tcb_error *err)
{
    (void)seq, (void)ctx;
    return ((model *)self)->mode == 0 ? tcb_fail(err, TCB_ERR_INPUT, "faulty: refusing to fit")
                                      : TCB_OK;
}

static int fy_transfer(void *self, const tcb_sequence *seq, int i, int j, const float *src, int n,
                       float *out, tcb_rng *rng, tcb_error *err)
{
    (void)seq, (void)i, (void)j, (void)rng;
    model *m = self;
    memcpy(out, src, (size_t)n * 3 * sizeof(float));
    if (m->mode == 4 && m->calls++ >= m->at) {
        for (int v = 0; v < n; v++) out[3 * v] = (float)v, out[3 * v + 1] = out[3 * v + 2] = 0;
        return TCB_OK;
    }
    if (m->mode == 4 || m->calls++ != m->at) return TCB_OK;
    if (m->mode == 1) return tcb_fail(err, TCB_ERR_NUMERIC, "faulty: loss is NaN");
    out[n / 2 * 3 + 1] = m->mode == 3 ? 1e30f : NAN;
    return TCB_OK;
}

static int tp_create(const char *params_json, void **self, tcb_error *err)
{
    return create_as("thread_probe", params_json, self, err);
}

static int tp_fit(void *self, const tcb_sequence *seq, const tcb_fit_ctx *ctx, tcb_error *err)
{
    (void)seq;
    model *m = self;
    m->fit_threads = ctx->n_threads;
    if (omp_get_max_threads() != ctx->n_threads)
        return tcb_fail(err, TCB_ERR_INTERNAL, "thread_probe: fit given %d threads runs with %d", ctx->n_threads,
                        omp_get_max_threads());
    return TCB_OK;
}

static int tp_transfer(void *self, const tcb_sequence *seq, int i, int j, const float *src, int n,
                       float *out, tcb_rng *rng, tcb_error *err)
{
    (void)seq, (void)i, (void)j, (void)rng;
    const model *m = self;
    memcpy(out, src, (size_t)n * 3 * sizeof(float));
    if (omp_get_max_threads() != m->fit_threads)
        return tcb_fail(err, TCB_ERR_INTERNAL, "thread_probe: transfer runs with %d threads, the fit was given %d",
                        omp_get_max_threads(), m->fit_threads);
    return TCB_OK;
}

static void destroy(void *self) { free(self); }

static const tcb_method_ops slow_noisy = {
    .abi_version = TCB_METHOD_ABI_VERSION,
    .name = "slow_noisy",
    .description = "test only: oracle plus seeded noise, checkpointed, optionally slow",
    .create = sn_create,
    .fit = sn_fit,
    .transfer = sn_transfer,
    .reconstruct = sn_reconstruct,
    .save = sn_save,
    .load = sn_load,
    .destroy = destroy,
};

static const tcb_method_ops faulty = {
    .abi_version = TCB_METHOD_ABI_VERSION,
    .name = "faulty",
    .description = "test only: fails in fit or transfer on purpose",
    .create = fy_create,
    .fit = fy_fit,
    .transfer = fy_transfer,
    .destroy = destroy,
};

static const tcb_method_ops thread_probe = {
    .abi_version = TCB_METHOD_ABI_VERSION,
    .name = "thread_probe",
    .description = "test only: fails unless fit and transfer run with the cell's thread count",
    .create = tp_create,
    .fit = tp_fit,
    .transfer = tp_transfer,
    .destroy = destroy,
};

const tcb_method_ops *const *tcb_plugin_methods(int *count);
const tcb_method_ops *const *tcb_plugin_methods(int *count)
{
    static const tcb_method_ops *const tables[] = {&slow_noisy, &faulty, &thread_probe};
    *count = 3;
    return tables;
}
