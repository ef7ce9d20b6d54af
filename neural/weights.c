#include "neural/weights.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tcb/fsutil.h"
#include "tcb/json.h"

static size_t total_floats(const tcb_weight_parts *w)
{
    size_t n = 0;
    for (int k = 0; k < w->n; k++) n += w->count[k];
    return n;
}

/* x86 is little-endian already, but the files are defined as LE so that
 * they read the same anywhere: bytes are composed explicitly. */
static void put_le(unsigned char *dst, float x)
{
    uint32_t u;
    memcpy(&u, &x, 4);
    for (int k = 0; k < 4; k++) dst[k] = (unsigned char)(u >> (8 * k));
}

static float get_le(const unsigned char *p)
{
    uint32_t u = (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
    float x;
    memcpy(&x, &u, 4);
    return x;
}

static int write_parts(FILE *fp, const tcb_weight_parts *w)
{
    unsigned char buf[4096 * 4];
    for (int k = 0; k < w->n; k++)
        for (size_t i = 0; i < w->count[k];) {
            size_t n = 0;
            for (; n < 4096 && i < w->count[k]; n++, i++) put_le(buf + 4 * n, w->data[k][i]);
            if (fwrite(buf, 4, n, fp) != n) return 0;
        }
    return 1;
}

static void read_parts(const unsigned char *p, const tcb_weight_parts *w)
{
    for (int k = 0; k < w->n; k++)
        for (size_t i = 0; i < w->count[k]; i++, p += 4) w->data[k][i] = get_le(p);
}

int tcb_weights_write(const char *path, const tcb_weight_parts *w, tcb_error *err)
{
    tcb_atomic_file af;
    int rc = tcb_atomic_open(&af, path, err);
    if (rc) return rc;
    if (!write_parts(af.fp, w)) return tcb_atomic_fail(&af, err);
    return tcb_atomic_commit(&af, err);
}

int tcb_weights_read(const char *path, const tcb_weight_parts *w, tcb_error *err)
{
    char *data;
    size_t len, n = total_floats(w);
    int rc = tcb_read_file(path, &data, &len, err);
    if (rc) return rc;
    if (len != n * 4) rc = tcb_fail(err, TCB_ERR_INPUT, "%s: %zu bytes, expected %zu (%zu float32)", path, len,
                                    n * 4, n);
    else read_parts((const unsigned char *)data, w);
    free(data);
    return rc;
}

void tcb_manifest_add_tensor(cJSON *tensors, const char *name, const int *shape, int rank, size_t offset)
{
    cJSON *t = cJSON_CreateObject(), *dims = cJSON_CreateArray();
    size_t count = 1;
    for (int k = 0; k < rank; k++) {
        cJSON_AddItemToArray(dims, cJSON_CreateNumber(shape[k]));
        count *= (size_t)shape[k];
    }
    cJSON_AddStringToObject(t, "name", name);
    cJSON_AddItemToObject(t, "shape", dims);
    cJSON_AddNumberToObject(t, "offset", (double)offset);
    cJSON_AddNumberToObject(t, "count", (double)count);
    cJSON_AddItemToArray(tensors, t);
}

int tcb_manifest_check(const cJSON *got, const cJSON *want, const char *where, tcb_error *err)
{
    if (cJSON_Compare(got, want, 1)) return TCB_OK;
    if (cJSON_IsObject(want) || cJSON_IsArray(want)) {
        if (cJSON_GetArraySize(got) != cJSON_GetArraySize(want) ||
            cJSON_IsObject(got) != cJSON_IsObject(want) || cJSON_IsArray(got) != cJSON_IsArray(want))
            return tcb_fail(err, TCB_ERR_INPUT, "%s: does not match this model's layout", where);
        int i = 0;
        for (const cJSON *w = want->child; w; w = w->next, i++) {
            char sub[TCB_ERRMSG_MAX / 2];
            const cJSON *g = cJSON_IsObject(want) ? cJSON_GetObjectItemCaseSensitive(got, w->string)
                                                  : cJSON_GetArrayItem(got, i);
            if (cJSON_IsObject(want)) snprintf(sub, sizeof sub, "%s.%s", where, w->string);
            else snprintf(sub, sizeof sub, "%s[%d]", where, i);
            int rc = tcb_manifest_check(g, w, sub, err);
            if (rc) return rc;
        }
    }
    char *text = cJSON_PrintUnformatted(want);
    int rc = tcb_fail(err, TCB_ERR_INPUT, "%s: expected %s for this model", where, text ? text : "another value");
    free(text);
    return rc;
}

int tcb_weights_export(const char *bin_path, const char *manifest_path, const cJSON *manifest,
                       const tcb_weight_parts *w, tcb_error *err)
{
    int rc = tcb_weights_write(bin_path, w, err);
    return rc ? rc : tcb_json_save(manifest_path, manifest, err);
}

int tcb_weights_import(const char *bin_path, const char *manifest_path, const cJSON *want,
                       const tcb_weight_parts *w, tcb_error *err)
{
    cJSON *got;
    int rc = tcb_json_load(manifest_path, &got, err);
    if (rc) return rc;
    rc = tcb_manifest_check(got, want, manifest_path, err);
    cJSON_Delete(got);
    return rc ? rc : tcb_weights_read(bin_path, w, err);
}

#define HDR 24

int tcb_model_file_write(const char *path, const char magic[8], uint64_t seed, const cJSON *manifest,
                         const tcb_weight_parts *w, tcb_error *err)
{
    char *text = cJSON_Print(manifest);
    if (!text) return tcb_fail(err, TCB_ERR_NOMEM, "%s: cannot serialize the manifest", path);
    uint64_t mlen = strlen(text);
    tcb_atomic_file af;
    int rc = tcb_atomic_open(&af, path, err);
    if (!rc) {
        int ok = fwrite(magic, 1, 8, af.fp) == 8 && fwrite(&seed, 8, 1, af.fp) == 1 &&
                 fwrite(&mlen, 8, 1, af.fp) == 1 && fwrite(text, 1, mlen, af.fp) == mlen && write_parts(af.fp, w);
        rc = ok ? tcb_atomic_commit(&af, err) : tcb_atomic_fail(&af, err);
    }
    free(text);
    return rc;
}

int tcb_model_file_read(const char *path, const char magic[8], const cJSON *want, uint64_t *seed,
                        const tcb_weight_parts *w, tcb_error *err)
{
    char *buf = NULL;
    size_t len = 0, n = total_floats(w);
    uint64_t s = 0, mlen = 0;
    int rc = tcb_read_file(path, &buf, &len, err);
    if (rc) return rc;
    if (len >= HDR) memcpy(&s, buf + 8, 8), memcpy(&mlen, buf + 16, 8);
    if (len < HDR || memcmp(buf, magic, 8) || mlen > len - HDR)
        rc = tcb_fail(err, TCB_ERR_INPUT, "%s: not a %.8s model checkpoint (bad magic or length)", path, magic);
    cJSON *got = NULL;
    if (!rc) {
        char *text = malloc(mlen + 1);
        if (!text) rc = tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", path);
        else {
            memcpy(text, buf + HDR, mlen), text[mlen] = '\0';
            rc = tcb_json_parse(text, path, &got, err);
            free(text);
        }
    }
    if (!rc) rc = tcb_manifest_check(got, want, path, err);
    if (!rc && len - HDR - mlen != n * 4)
        rc = tcb_fail(err, TCB_ERR_INPUT, "%s: %zu bytes of weights, expected %zu (%zu float32)", path,
                      (size_t)(len - HDR - mlen), n * 4, n);
    if (!rc) read_parts((const unsigned char *)buf + HDR + mlen, w), *seed = s;
    cJSON_Delete(got);
    free(buf);
    return rc;
}

int tcb_model_file_seed(const char *path, const char magic[8], uint64_t *seed, tcb_error *err)
{
    unsigned char head[HDR];
    FILE *f = fopen(path, "rb");
    if (!f) return tcb_fail(err, TCB_ERR_IO, "%s: cannot open", path);
    size_t got = fread(head, 1, HDR, f);
    fclose(f);
    if (got < HDR || memcmp(head, magic, 8))
        return tcb_fail(err, TCB_ERR_INPUT, "%s: not a %.8s model checkpoint (bad magic or length)", path, magic);
    memcpy(seed, head + 8, 8);
    return TCB_OK;
}
