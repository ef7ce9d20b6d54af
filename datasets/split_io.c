/* Split files: JSON, format "tcbench-split/1".
 *   { "format": "tcbench-split/1", "dataset": "anim", "sequence": "cat_walk",
 *     "role": "validation", "n_frames": 35,
 *     "blocks": [ { "name": "50002", "start": 0, "n_frames": 120 }, ... ],
 *     "seed": 2021, "n_pairs": 500, "pairs": [[i, j], ...] }
 * "blocks" (the sequence's blocks, tcb/block.h) is written only for a
 * sequence that has them (DFAUST), so single-block files are unchanged.
 * Loading checks every key, type and pair (both frames of a pair in one
 * block), so a hand-edited or truncated file fails with the file and key
 * named instead of skewing an evaluation. */
#include "tcb/split.h"

#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tcb/fsutil.h"
#include "tcb/json.h"

#define SPLIT_FORMAT "tcbench-split/1"
#define SPLIT_SEED_MAX 9007199254740992LL /* 2^53: exact in a JSON number */

static cJSON *blocks_to_json(const tcb_split *s)
{
    cJSON *arr = cJSON_CreateArray();
    int ok = arr != NULL;
    for (int k = 0; ok && k < s->n_blocks; k++) {
        cJSON *b = cJSON_CreateObject();
        ok = b && cJSON_AddItemToArray(arr, b) && cJSON_AddStringToObject(b, "name", s->blocks[k].name) &&
             cJSON_AddNumberToObject(b, "start", s->blocks[k].start) &&
             cJSON_AddNumberToObject(b, "n_frames", s->blocks[k].n_frames);
    }
    if (ok) return arr;
    cJSON_Delete(arr);
    return NULL;
}

static cJSON *split_to_json(const tcb_split *s)
{
    /* Written as raw text: cJSON prints numbers with 15 significant digits. */
    char seed[32];
    snprintf(seed, sizeof seed, "%llu", (unsigned long long)s->seed);
    cJSON *root = cJSON_CreateObject(), *pairs = cJSON_CreateArray();
    int ok = root && pairs && cJSON_AddStringToObject(root, "format", SPLIT_FORMAT) &&
             cJSON_AddStringToObject(root, "dataset", s->dataset) &&
             cJSON_AddStringToObject(root, "sequence", s->sequence) &&
             cJSON_AddStringToObject(root, "role", tcb_role_name(s->role)) &&
             cJSON_AddNumberToObject(root, "n_frames", s->n_frames);
    if (ok && s->n_blocks > 0) {
        cJSON *blocks = blocks_to_json(s);
        ok = blocks && cJSON_AddItemToObject(root, "blocks", blocks);
    }
    ok = ok && cJSON_AddRawToObject(root, "seed", seed) &&
         cJSON_AddNumberToObject(root, "n_pairs", s->n_pairs);
    for (int p = 0; ok && p < s->n_pairs; p++) {
        cJSON *pair = cJSON_CreateIntArray(s->pairs + 2 * p, 2);
        ok = pair && cJSON_AddItemToArray(pairs, pair);
    }
    if (ok && cJSON_AddItemToObject(root, "pairs", pairs)) return root;
    cJSON_Delete(pairs);
    cJSON_Delete(root);
    return NULL;
}

int tcb_split_save(const char *path, const tcb_split *s, tcb_error *err)
{
    if (s->seed > (uint64_t)SPLIT_SEED_MAX)
        return tcb_fail(err, TCB_ERR_INPUT,
                        "%s.seed: %llu exceeds 2^53, the largest integer JSON stores exactly",
                        path, (unsigned long long)s->seed);
    cJSON *root = split_to_json(s);
    if (!root) return tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", path);
    int rc = tcb_json_save(path, root, err);
    cJSON_Delete(root);
    return rc;
}

char *tcb_split_json(const tcb_split *s)
{
    cJSON *root = split_to_json(s);
    char *text = root ? cJSON_PrintUnformatted(root) : NULL; /* cJSON allocates with malloc */
    cJSON_Delete(root);
    return text;
}

static int load_name(const cJSON *root, const char *key, const char *where, char *out,
                     size_t size, tcb_error *err)
{
    const char *v;
    int rc = tcb_json_str(root, key, where, 1, NULL, &v, err);
    if (rc) return rc;
    if (strlen(v) >= size)
        return tcb_fail(err, TCB_ERR_INPUT, "%s.%s: longer than %zu characters", where, key,
                        size - 1);
    snprintf(out, size, "%s", v);
    return TCB_OK;
}

static int load_header(const cJSON *root, const char *path, tcb_split *out, tcb_error *err)
{
    static const char *const keys[] = {"format", "dataset", "sequence", "role",  "n_frames",
                                       "blocks", "seed",    "n_pairs",  "pairs", NULL};
    const char *format, *role;
    long long n_frames, seed, n_pairs;
    int rc = tcb_json_expect_keys(root, path, keys, err);
    if (!rc) rc = tcb_json_str(root, "format", path, 1, NULL, &format, err);
    if (!rc && strcmp(format, SPLIT_FORMAT) != 0)
        return tcb_fail(err, TCB_ERR_INPUT, "%s.format: expected \"%s\", got \"%s\"", path,
                        SPLIT_FORMAT, format);
    if (!rc) rc = load_name(root, "dataset", path, out->dataset, sizeof out->dataset, err);
    if (!rc) rc = load_name(root, "sequence", path, out->sequence, sizeof out->sequence, err);
    if (!rc) rc = tcb_json_str(root, "role", path, 1, NULL, &role, err);
    if (!rc && tcb_role_parse(role, &out->role) != 0)
        return tcb_fail(err, TCB_ERR_INPUT,
                        "%s.role: unknown role \"%s\" (expected train, validation or test)", path,
                        role);
    if (!rc) rc = tcb_json_int(root, "n_frames", path, 1, 0, 2, INT_MAX, &n_frames, err);
    if (!rc) rc = tcb_json_int(root, "seed", path, 1, 0, 0, SPLIT_SEED_MAX, &seed, err);
    if (!rc) rc = tcb_json_int(root, "n_pairs", path, 1, 0, 0, INT_MAX, &n_pairs, err);
    if (rc) return rc;
    out->n_frames = (int)n_frames;
    out->seed = (uint64_t)seed;
    out->n_pairs = (int)n_pairs;
    return TCB_OK;
}

static int load_block(const cJSON *o, const char *where, tcb_block *b, tcb_error *err)
{
    static const char *const keys[] = {"name", "start", "n_frames", NULL};
    long long start, n_frames;
    int rc = tcb_json_expect_keys(o, where, keys, err);
    if (!rc) rc = load_name(o, "name", where, b->name, sizeof b->name, err);
    if (!rc) rc = tcb_json_int(o, "start", where, 1, 0, 0, INT_MAX, &start, err);
    if (!rc) rc = tcb_json_int(o, "n_frames", where, 1, 0, 0, INT_MAX, &n_frames, err);
    if (rc) return rc;
    b->start = (int)start, b->n_frames = (int)n_frames;
    return TCB_OK;
}

/* The optional "blocks", checked against n_frames (tcb_blocks_check). */
static int load_blocks(const cJSON *root, const char *path, tcb_split *out, tcb_error *err)
{
    const cJSON *arr = cJSON_GetObjectItemCaseSensitive(root, "blocks");
    if (!arr) return TCB_OK;
    char where[TCB_PATH_MAX + 32];
    snprintf(where, sizeof where, "%s.blocks", path);
    int n = cJSON_IsArray(arr) ? cJSON_GetArraySize(arr) : 0;
    if (n < 1) return tcb_fail(err, TCB_ERR_INPUT, "%s: expected a non-empty array of blocks", where);
    out->blocks = calloc((size_t)n, sizeof *out->blocks);
    if (!out->blocks) return tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", path);
    out->n_blocks = n;
    int k = 0;
    for (const cJSON *b = arr->child; b; b = b->next, k++) {
        char bw[TCB_PATH_MAX + 48];
        snprintf(bw, sizeof bw, "%s[%d]", where, k);
        int rc = load_block(b, bw, &out->blocks[k], err);
        if (rc) return rc;
    }
    return tcb_blocks_check(out->blocks, n, out->n_frames, where, err);
}

/* One frame index of pairs[p]: an integer in [0, n_frames). */
static int load_frame(const cJSON *v, const char *path, int p, int e, int n_frames,
                      int32_t *out, tcb_error *err)
{
    if (!cJSON_IsNumber(v) || v->valuedouble != floor(v->valuedouble))
        return tcb_fail(err, TCB_ERR_INPUT, "%s.pairs[%d][%d]: expected an integer frame index",
                        path, p, e);
    if (v->valuedouble < 0 || v->valuedouble >= n_frames)
        return tcb_fail(err, TCB_ERR_INPUT, "%s.pairs[%d][%d]: frame %g outside [0, %d)", path,
                        p, e, v->valuedouble, n_frames);
    *out = (int32_t)v->valuedouble;
    return TCB_OK;
}

static int load_pairs(const cJSON *root, const char *path, tcb_split *out, tcb_error *err)
{
    const cJSON *pairs = cJSON_GetObjectItemCaseSensitive(root, "pairs");
    if (!cJSON_IsArray(pairs))
        return tcb_fail(err, TCB_ERR_INPUT, "%s.pairs: expected an array of [i, j] pairs", path);
    int count = cJSON_GetArraySize(pairs);
    if (count != out->n_pairs)
        return tcb_fail(err, TCB_ERR_INPUT, "%s.pairs: %d pairs but n_pairs is %d", path, count,
                        out->n_pairs);
    out->pairs = malloc((size_t)(count > 0 ? count : 1) * 2 * sizeof(int32_t));
    if (!out->pairs) return tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", path);
    int p = 0;
    for (const cJSON *pair = pairs->child; pair; pair = pair->next, p++) {
        if (!cJSON_IsArray(pair) || cJSON_GetArraySize(pair) != 2)
            return tcb_fail(err, TCB_ERR_INPUT, "%s.pairs[%d]: expected [i, j]", path, p);
        int32_t *ij = out->pairs + 2 * p;
        int rc = load_frame(pair->child, path, p, 0, out->n_frames, &ij[0], err);
        if (!rc) rc = load_frame(pair->child->next, path, p, 1, out->n_frames, &ij[1], err);
        if (rc) return rc;
        if (ij[0] == ij[1])
            return tcb_fail(err, TCB_ERR_INPUT, "%s.pairs[%d]: i == j (%d)", path, p, (int)ij[0]);
        int lo, hi;
        tcb_block_find(out->blocks, out->n_blocks, out->n_frames, ij[0], &lo, &hi);
        if (ij[1] < lo || ij[1] >= hi)
            return tcb_fail(err, TCB_ERR_INPUT, "%s.pairs[%d]: frames %d and %d are in different blocks",
                            path, p, (int)ij[0], (int)ij[1]);
    }
    return TCB_OK;
}

int tcb_split_load(const char *path, tcb_split *out, tcb_error *err)
{
    memset(out, 0, sizeof *out);
    cJSON *root;
    int rc = tcb_json_load(path, &root, err);
    if (rc) return rc;
    rc = load_header(root, path, out, err);
    if (!rc) rc = load_blocks(root, path, out, err);
    if (!rc) rc = load_pairs(root, path, out, err);
    cJSON_Delete(root);
    if (rc) tcb_split_free(out);
    return rc;
}
