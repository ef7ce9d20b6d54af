/* Split files: JSON, format "tcbench-split/1".
 *   { "format": "tcbench-split/1", "dataset": "anim", "sequence": "cat_walk",
 *     "role": "validation", "n_frames": 35,
 *     "blocks": [ { "name": "50002", "start": 0, "n_frames": 120 }, ... ],
 *     "seed": 2021, "n_pairs": 500, "pairs": [[i, j], ...] }
 * "blocks" (the sequence's blocks, tcb/block.h) is written only for a
 * sequence that has them (DFAUST), so single-block files are unchanged.
 * A clip split (tcb_clips_make) is format "tcbench-clips/1", the same
 * header with "clip_frames", "n_clips" and "starts" instead of "n_pairs"
 * and "pairs":
 *   { "format": "tcbench-clips/1", "dataset", "sequence", "role", "n_frames",
 *     ["blocks",] "seed", "clip_frames": 17, "n_clips": 10, "starts": [s, ...] }
 * Loading checks every key, type and pair (both frames of a pair in one
 * block) or start (the clip inside one block, starts ascending), so a
 * hand-edited or truncated file fails with the file and key named instead
 * of skewing an evaluation. */
#include "tcb/split.h"

#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tcb/fsutil.h"
#include "tcb/json.h"

#define SPLIT_FORMAT "tcbench-split/1"
#define CLIPS_FORMAT "tcbench-clips/1"
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

/* "n_pairs" and "pairs", or a clip split's "clip_frames", "n_clips" and
 * "starts". */
static int add_frames(cJSON *root, const tcb_split *s)
{
    if (s->clip_frames > 0) {
        cJSON *starts = cJSON_CreateIntArray(s->starts, s->n_clips);
        return cJSON_AddNumberToObject(root, "clip_frames", s->clip_frames) &&
               cJSON_AddNumberToObject(root, "n_clips", s->n_clips) && starts &&
               cJSON_AddItemToObject(root, "starts", starts);
    }
    cJSON *pairs = cJSON_CreateArray();
    int ok = pairs && cJSON_AddNumberToObject(root, "n_pairs", s->n_pairs);
    for (int p = 0; ok && p < s->n_pairs; p++) {
        cJSON *pair = cJSON_CreateIntArray(s->pairs + 2 * p, 2);
        ok = pair && cJSON_AddItemToArray(pairs, pair);
    }
    if (ok && cJSON_AddItemToObject(root, "pairs", pairs)) return 1;
    cJSON_Delete(pairs);
    return 0;
}

static cJSON *split_to_json(const tcb_split *s)
{
    /* Written as raw text: cJSON prints numbers with 15 significant digits. */
    char seed[32];
    snprintf(seed, sizeof seed, "%llu", (unsigned long long)s->seed);
    cJSON *root = cJSON_CreateObject();
    int ok = root && cJSON_AddStringToObject(root, "format", s->clip_frames > 0 ? CLIPS_FORMAT : SPLIT_FORMAT) &&
             cJSON_AddStringToObject(root, "dataset", s->dataset) &&
             cJSON_AddStringToObject(root, "sequence", s->sequence) &&
             cJSON_AddStringToObject(root, "role", tcb_role_name(s->role)) &&
             cJSON_AddNumberToObject(root, "n_frames", s->n_frames);
    if (ok && s->n_blocks > 0) {
        cJSON *blocks = blocks_to_json(s);
        ok = blocks && cJSON_AddItemToObject(root, "blocks", blocks);
    }
    ok = ok && cJSON_AddRawToObject(root, "seed", seed) && add_frames(root, s);
    if (ok) return root;
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
    static const char *const clip_keys[] = {"format", "dataset", "sequence", "role",    "n_frames", "blocks",
                                            "seed",   "clip_frames", "n_clips", "starts", NULL};
    const char *format, *role;
    long long n_frames, seed, count;
    int rc = tcb_json_expect_object(root, path, err);
    if (!rc) rc = tcb_json_str(root, "format", path, 1, NULL, &format, err);
    int clips = !rc && strcmp(format, CLIPS_FORMAT) == 0;
    if (!rc && !clips && strcmp(format, SPLIT_FORMAT) != 0)
        return tcb_fail(err, TCB_ERR_INPUT, "%s.format: expected \"%s\" or \"%s\", got \"%s\"", path,
                        SPLIT_FORMAT, CLIPS_FORMAT, format);
    if (!rc) rc = tcb_json_expect_keys(root, path, clips ? clip_keys : keys, err);
    if (!rc) rc = load_name(root, "dataset", path, out->dataset, sizeof out->dataset, err);
    if (!rc) rc = load_name(root, "sequence", path, out->sequence, sizeof out->sequence, err);
    if (!rc) rc = tcb_json_str(root, "role", path, 1, NULL, &role, err);
    if (!rc && tcb_role_parse(role, &out->role) != 0)
        return tcb_fail(err, TCB_ERR_INPUT,
                        "%s.role: unknown role \"%s\" (expected train, validation or test)", path,
                        role);
    if (!rc) rc = tcb_json_int(root, "n_frames", path, 1, 0, 2, INT_MAX, &n_frames, err);
    if (!rc) rc = tcb_json_int(root, "seed", path, 1, 0, 0, SPLIT_SEED_MAX, &seed, err);
    if (!rc) rc = tcb_json_int(root, clips ? "n_clips" : "n_pairs", path, 1, 0, clips, INT_MAX, &count, err);
    if (rc) return rc;
    out->n_frames = (int)n_frames;
    out->seed = (uint64_t)seed;
    if (!clips) {
        out->n_pairs = (int)count;
        return TCB_OK;
    }
    out->n_clips = (int)count;
    rc = tcb_json_int(root, "clip_frames", path, 1, 0, 2, n_frames, &count, err);
    out->clip_frames = (int)count;
    return rc;
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

/* starts[c]: an integer s, the clip [s, s + clip_frames) inside one block,
 * after starts[c - 1]. */
static int load_start(const cJSON *v, const char *path, int c, const tcb_split *s, tcb_error *err)
{
    int lo, hi;
    if (!cJSON_IsNumber(v) || v->valuedouble != floor(v->valuedouble) || v->valuedouble < 0 ||
        v->valuedouble >= s->n_frames)
        return tcb_fail(err, TCB_ERR_INPUT, "%s.starts[%d]: expected a frame index in [0, %d)", path, c,
                        s->n_frames);
    int32_t f = (int32_t)v->valuedouble;
    tcb_block_find(s->blocks, s->n_blocks, s->n_frames, f, &lo, &hi);
    if (f + s->clip_frames > hi)
        return tcb_fail(err, TCB_ERR_INPUT, "%s.starts[%d]: the clip of %d frames from %d ends past frame %d%s",
                        path, c, s->clip_frames, (int)f, hi - 1, s->n_blocks ? " (its block's last)" : "");
    if (c > 0 && f <= s->starts[c - 1])
        return tcb_fail(err, TCB_ERR_INPUT, "%s.starts[%d]: %d does not follow %d (starts are ascending, distinct)",
                        path, c, (int)f, (int)s->starts[c - 1]);
    s->starts[c] = f;
    return TCB_OK;
}

static int load_starts(const cJSON *root, const char *path, tcb_split *out, tcb_error *err)
{
    const cJSON *starts = cJSON_GetObjectItemCaseSensitive(root, "starts");
    if (!cJSON_IsArray(starts))
        return tcb_fail(err, TCB_ERR_INPUT, "%s.starts: expected an array of start frames", path);
    if (cJSON_GetArraySize(starts) != out->n_clips)
        return tcb_fail(err, TCB_ERR_INPUT, "%s.starts: %d starts but n_clips is %d", path,
                        cJSON_GetArraySize(starts), out->n_clips);
    out->starts = malloc((size_t)out->n_clips * sizeof *out->starts);
    if (!out->starts) return tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", path);
    int c = 0, rc = TCB_OK;
    for (const cJSON *v = starts->child; v && !rc; v = v->next, c++) rc = load_start(v, path, c, out, err);
    return rc;
}

int tcb_split_load(const char *path, tcb_split *out, tcb_error *err)
{
    memset(out, 0, sizeof *out);
    cJSON *root;
    int rc = tcb_json_load(path, &root, err);
    if (rc) return rc;
    rc = load_header(root, path, out, err);
    if (!rc) rc = load_blocks(root, path, out, err);
    if (!rc) rc = out->clip_frames > 0 ? load_starts(root, path, out, err) : load_pairs(root, path, out, err);
    cJSON_Delete(root);
    if (rc) tcb_split_free(out);
    return rc;
}
