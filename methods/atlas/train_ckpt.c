#include "methods/atlas/train_ckpt.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tcb/fsutil.h"

#define MAGIC "TCBATRN2"

enum { I_ITERATIONS = 5, N_INTS = 10, N_REALS = 3 };
static const char *const int_names[N_INTS] = {"latent", "patches", "uv_samples", "loss",
                                              "delta", "iterations", "input_points",
                                              "frames", "pool_size", "parameter count"};
static const char *const real_names[N_REALS] = {"lr", "alpha_mc", "alpha_sciso"};

/* The settings block: what must match for a checkpoint to be continued. */
typedef struct settings {
    int64_t ints[N_INTS];
    double reals[N_REALS];
    uint64_t seed;
} settings;

/* The state block. */
typedef struct state {
    int64_t it;
    uint64_t rng[4];
    int64_t adam_t;
    double loss0;
    double seconds;
} state;

#define HEAD_BYTES (8 + sizeof(settings) + sizeof(state))

static settings settings_of(const tcb_atlas_trainer *t, const tcb_sequence *seq, uint64_t seed)
{
    const tcb_atlas_train_cfg *c = &t->cfg;
    return (settings){
        .ints = {t->model->C, t->model->P, c->M, c->loss, c->delta, c->iterations, t->N,
                 seq->n_frames, seq->pool_size, (int64_t)t->model->nparams},
        .reals = {c->lr, c->alpha_mc, c->alpha_sciso},
        .seed = seed,
    };
}

/* FNV-1a 64: a corruption check, not a security measure. */
static uint64_t fnv1a(uint64_t h, const void *data, size_t len)
{
    const unsigned char *p = data;
    for (size_t k = 0; k < len; k++) h = (h ^ p[k]) * 0x100000001b3ULL;
    return h;
}
#define FNV_OFFSET 0xcbf29ce484222325ULL

static int put(tcb_atomic_file *af, uint64_t *h, const void *data, size_t len)
{
    *h = fnv1a(*h, data, len);
    return fwrite(data, 1, len, af->fp) == len;
}

int tcb_atlas_train_ckpt_save(const tcb_atlas_trainer *t, const tcb_sequence *seq,
                              uint64_t seed, double seconds, const char *path, tcb_error *err)
{
    settings s = settings_of(t, seq, seed);
    state st = {.it = t->it, .adam_t = t->adam.t, .loss0 = t->loss0, .seconds = seconds};
    memcpy(st.rng, t->rng.s, sizeof st.rng);
    size_t n = t->model->nparams;
    tcb_atomic_file af;
    int rc = tcb_atomic_open(&af, path, err);
    if (rc) return rc;
    uint64_t h = FNV_OFFSET;
    int ok = put(&af, &h, MAGIC, 8) && put(&af, &h, &s, sizeof s) && put(&af, &h, &st, sizeof st) &&
             put(&af, &h, t->model->params, n * sizeof(float)) &&
             put(&af, &h, t->adam.m, n * sizeof(float)) && put(&af, &h, t->adam.v, n * sizeof(float));
    ok = ok && fwrite(&h, sizeof h, 1, af.fp) == 1;
    if (!ok) {
        tcb_atomic_abort(&af);
        return tcb_fail(err, TCB_ERR_IO, "%s: write failed", path);
    }
    return tcb_atomic_commit(&af, err);
}

/* The first setting that differs, described into msg; 0 when all match. */
static int describe_mismatch(const settings *want, const settings *got, char *msg, size_t size)
{
    for (int k = 0; k < N_INTS; k++)
        if (want->ints[k] != got->ints[k])
            return snprintf(msg, size, "%s is %lld, this training has %lld", int_names[k],
                            (long long)got->ints[k], (long long)want->ints[k]),
                   1;
    for (int k = 0; k < N_REALS; k++)
        if (want->reals[k] != got->reals[k])
            return snprintf(msg, size, "%s is %.17g, this training has %.17g", real_names[k],
                            got->reals[k], want->reals[k]),
                   1;
    if (want->seed != got->seed)
        return snprintf(msg, size, "seed is %llu, this training has %llu",
                        (unsigned long long)got->seed, (unsigned long long)want->seed),
               1;
    return 0;
}

static int check_file(const char *buf, size_t len, size_t n, const settings *want, const char *path,
                      tcb_error *err)
{
    size_t expect = HEAD_BYTES + 3 * n * sizeof(float) + sizeof(uint64_t);
    if (len < 8 || memcmp(buf, MAGIC, 8) != 0)
        return tcb_fail(err, TCB_ERR_INPUT, "%s: not an atlas training checkpoint (bad magic)", path);
    if (len < HEAD_BYTES)
        return tcb_fail(err, TCB_ERR_INPUT, "%s: truncated (%zu bytes, expected %zu)", path, len, expect);
    settings got;
    memcpy(&got, buf + 8, sizeof got);
    char why[256];
    if (describe_mismatch(want, &got, why, sizeof why))
        return tcb_fail(err, TCB_ERR_INPUT, "%s: made by another training: %s", path, why);
    if (len != expect)
        return tcb_fail(err, TCB_ERR_INPUT, "%s: truncated or padded (%zu bytes, expected %zu)", path, len,
                        expect);
    uint64_t stored;
    memcpy(&stored, buf + len - sizeof stored, sizeof stored);
    if (fnv1a(FNV_OFFSET, buf, len - sizeof stored) != stored)
        return tcb_fail(err, TCB_ERR_INPUT, "%s: checksum mismatch (corrupted file)", path);
    return TCB_OK;
}

int tcb_atlas_train_ckpt_load(tcb_atlas_trainer *t, const tcb_sequence *seq, uint64_t seed,
                              const char *path, double *seconds, tcb_error *err)
{
    char *buf = NULL;
    size_t len = 0, n = t->model->nparams;
    settings want = settings_of(t, seq, seed);
    int rc = tcb_read_file(path, &buf, &len, err);
    if (!rc) rc = check_file(buf, len, n, &want, path, err);
    state st;
    if (!rc) memcpy(&st, buf + 8 + sizeof(settings), sizeof st);
    if (!rc && (st.it < 0 || st.it > want.ints[I_ITERATIONS] || st.adam_t < 0))
        rc = tcb_fail(err, TCB_ERR_INPUT, "%s: iteration %lld outside 0..%lld", path, (long long)st.it,
                      (long long)want.ints[I_ITERATIONS]);
    if (!rc && !(st.seconds >= 0 && st.seconds < INFINITY))
        rc = tcb_fail(err, TCB_ERR_INPUT, "%s: training time %g s is not a duration", path, st.seconds);
    if (!rc) {
        const char *p = buf + HEAD_BYTES;
        size_t bytes = n * sizeof(float);
        memcpy(t->model->params, p, bytes);
        memcpy(t->adam.m, p + bytes, bytes);
        memcpy(t->adam.v, p + 2 * bytes, bytes);
        memcpy(t->rng.s, st.rng, sizeof st.rng);
        t->it = st.it, t->adam.t = st.adam_t, t->loss0 = st.loss0;
        *seconds = st.seconds;
    }
    free(buf);
    return rc;
}
