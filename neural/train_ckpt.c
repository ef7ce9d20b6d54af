#include "neural/train_ckpt.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tcb/fsutil.h"
#include "tcb/hash.h"


static size_t settings_bytes(const tcb_ckpt_settings *s)
{
    return (size_t)s->n_ints * sizeof(int64_t) + (size_t)s->n_reals * sizeof(double) + sizeof(uint64_t);
}

static size_t head_bytes(const tcb_ckpt_settings *s)
{
    return 8 + settings_bytes(s) + sizeof(tcb_train_progress);
}

static size_t file_bytes(const tcb_ckpt_settings *s, const tcb_ckpt_array *arrays, int n_arrays)
{
    size_t len = head_bytes(s) + sizeof(uint64_t);
    for (int k = 0; k < n_arrays; k++) len += arrays[k].n * sizeof(float);
    return len;
}

static int put(tcb_atomic_file *af, uint64_t *h, const void *data, size_t len)
{
    *h = tcb_fnv1a64(*h, data, len);
    return fwrite(data, 1, len, af->fp) == len;
}

int tcb_train_ckpt_write(const char *path, const char magic[8], const tcb_ckpt_settings *s,
                         const tcb_train_progress *p, const tcb_ckpt_array *arrays, int n_arrays,
                         tcb_error *err)
{
    tcb_atomic_file af;
    int rc = tcb_atomic_open(&af, path, err);
    if (rc) return rc;
    uint64_t h = TCB_FNV1A64_OFFSET;
    int ok = put(&af, &h, magic, 8) && put(&af, &h, s->ints, (size_t)s->n_ints * sizeof(int64_t)) &&
             put(&af, &h, s->reals, (size_t)s->n_reals * sizeof(double)) &&
             put(&af, &h, &s->seed, sizeof s->seed) && put(&af, &h, p, sizeof *p);
    for (int k = 0; ok && k < n_arrays; k++) ok = put(&af, &h, arrays[k].data, arrays[k].n * sizeof(float));
    ok = ok && fwrite(&h, sizeof h, 1, af.fp) == 1;
    if (!ok) return tcb_atomic_fail(&af, err);
    return tcb_atomic_commit(&af, err);
}

/* The first setting of `got` (the file's, at buf) that differs from want,
 * described into msg; 0 when all match. */
static int describe_mismatch(const tcb_ckpt_settings *want, const char *buf, char *msg, size_t size)
{
    for (int k = 0; k < want->n_ints; k++) {
        int64_t got;
        memcpy(&got, buf + (size_t)k * sizeof got, sizeof got);
        if (got != want->ints[k])
            return snprintf(msg, size, "%s is %lld, this training has %lld", want->int_names[k], (long long)got,
                            (long long)want->ints[k]),
                   1;
    }
    buf += (size_t)want->n_ints * sizeof(int64_t);
    for (int k = 0; k < want->n_reals; k++) {
        double got;
        memcpy(&got, buf + (size_t)k * sizeof got, sizeof got);
        if (got != want->reals[k])
            return snprintf(msg, size, "%s is %.17g, this training has %.17g", want->real_names[k], got,
                            want->reals[k]),
                   1;
    }
    uint64_t seed;
    memcpy(&seed, buf + (size_t)want->n_reals * sizeof(double), sizeof seed);
    if (seed != want->seed)
        return snprintf(msg, size, "seed is %llu, this training has %llu", (unsigned long long)seed,
                        (unsigned long long)want->seed),
               1;
    return 0;
}

static int check_file(const char *buf, size_t len, const char magic[8], const char *what,
                      const tcb_ckpt_settings *want, size_t expect, const char *path, tcb_error *err)
{
    if (len < 8 || memcmp(buf, magic, 8) != 0)
        return tcb_fail(err, TCB_ERR_INPUT, "%s: not %s (bad magic)", path, what);
    if (len < head_bytes(want))
        return tcb_fail(err, TCB_ERR_INPUT, "%s: truncated (%zu bytes, expected %zu)", path, len, expect);
    char why[256];
    if (describe_mismatch(want, buf + 8, why, sizeof why))
        return tcb_fail(err, TCB_ERR_INPUT, "%s: made by another training: %s", path, why);
    if (len != expect)
        return tcb_fail(err, TCB_ERR_INPUT, "%s: truncated or padded (%zu bytes, expected %zu)", path, len,
                        expect);
    uint64_t stored;
    memcpy(&stored, buf + len - sizeof stored, sizeof stored);
    if (tcb_fnv1a64(TCB_FNV1A64_OFFSET, buf, len - sizeof stored) != stored)
        return tcb_fail(err, TCB_ERR_INPUT, "%s: checksum mismatch (corrupted file)", path);
    return TCB_OK;
}

int tcb_train_ckpt_read(const char *path, const char magic[8], const char *what,
                        const tcb_ckpt_settings *want, int64_t max_it, tcb_train_progress *p,
                        const tcb_ckpt_array *arrays, int n_arrays, tcb_error *err)
{
    char *buf = NULL;
    size_t len = 0, expect = file_bytes(want, arrays, n_arrays);
    int rc = tcb_read_file(path, &buf, &len, err);
    if (!rc) rc = check_file(buf, len, magic, what, want, expect, path, err);
    tcb_train_progress got;
    if (!rc) memcpy(&got, buf + 8 + settings_bytes(want), sizeof got);
    if (!rc && (got.it < 0 || got.it > max_it || got.adam_t < 0))
        rc = tcb_fail(err, TCB_ERR_INPUT, "%s: iteration %lld outside 0..%lld", path, (long long)got.it,
                      (long long)max_it);
    if (!rc && !(got.seconds >= 0 && got.seconds < INFINITY))
        rc = tcb_fail(err, TCB_ERR_INPUT, "%s: training time %g s is not a duration", path, got.seconds);
    if (!rc) {
        *p = got;
        const char *at = buf + head_bytes(want);
        for (int k = 0; k < n_arrays; k++) {
            memcpy(arrays[k].data, at, arrays[k].n * sizeof(float));
            at += arrays[k].n * sizeof(float);
        }
    }
    free(buf);
    return rc;
}

static tcb_ckpt_settings settings_of(const tcb_ckpt_spec *s)
{
    return (tcb_ckpt_settings){.n_ints = s->n_ints, .n_reals = s->n_reals, .int_names = s->int_names,
                               .real_names = s->real_names, .ints = s->ints, .reals = s->reals, .seed = s->seed};
}

int tcb_ckpt_spec_save(const tcb_ckpt_spec *s, double seconds, const char *path, tcb_error *err)
{
    const tcb_trainer_state *st = &s->state;
    tcb_ckpt_settings set = settings_of(s);
    tcb_train_progress p = {.it = *st->it, .adam_t = st->adam->t, .loss0 = *st->loss0, .seconds = seconds};
    if (st->rng) memcpy(p.rng, st->rng->s, sizeof p.rng); /* else zeros: a training that draws nothing */
    return tcb_train_ckpt_write(path, s->magic, &set, &p, s->arrays, s->n_arrays, err);
}

int tcb_ckpt_spec_load(const tcb_ckpt_spec *s, const char *path, double *seconds, tcb_error *err)
{
    const tcb_trainer_state *st = &s->state;
    tcb_ckpt_settings want = settings_of(s);
    tcb_train_progress p;
    int rc = tcb_train_ckpt_read(path, s->magic, s->what, &want, s->max_it, &p, s->arrays, s->n_arrays, err);
    if (rc) return rc;
    if (st->rng) memcpy(st->rng->s, p.rng, sizeof p.rng);
    *st->it = p.it, st->adam->t = p.adam_t, *st->loss0 = p.loss0;
    *seconds = p.seconds;
    return TCB_OK;
}
