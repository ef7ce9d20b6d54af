/* The run directory's config.json: the config of the cells it holds.
 *
 * The first run of a directory creates it (link(2) of a complete file:
 * exclusive, so two configs started at once cannot both be first); every
 * later run compares its own config with it and refuses to mix cells of
 * different settings in one directory, naming both configs and the first
 * setting that differs: a report would pool them as one method's numbers,
 * and a cell file records its method's params but not its dataset's frames,
 * normalization or pools. Only what decides a cell is compared, so the same
 * config is still the same run from another machine (other data roots,
 * plug-in paths, cache and splits directories), with other threads, under
 * another name, or with --cell, --shard, --only. --force takes the
 * directory over for the new config (its cells are recomputed as they are
 * selected); another --out keeps both. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "harness/internal.h"
#include "tcb/fsutil.h"
#include "tcb/json.h"

/* Keys of the normalized config (config_dump.c) that change no cell. */
static const char *const free_keys[] = {"name", "output", "splits_dir", "cache_dir", "plugins", "threads",
                                        "reference", NULL};
static const char *const free_dataset_keys[] = {"root", "optional", NULL};

static void drop_keys(cJSON *o, const char *const *keys)
{
    for (int k = 0; keys[k]; k++) cJSON_DeleteItemFromObjectCaseSensitive(o, keys[k]);
}

/* The parts of a normalized config that decide its cells. */
static void cell_settings(cJSON *config)
{
    drop_keys(config, free_keys);
    cJSON *datasets = cJSON_GetObjectItemCaseSensitive(config, "datasets");
    for (cJSON *d = cJSON_IsArray(datasets) ? datasets->child : NULL; d; d = d->next) drop_keys(d, free_dataset_keys);
}

/* A value for a message, cut short. */
static void show(const cJSON *v, char *out, size_t size)
{
    char *text = v ? cJSON_PrintUnformatted(v) : NULL;
    snprintf(out, size, "%s", v ? (text ? text : "?") : "absent");
    if (strlen(out) + 1 == size && size > 4) strcpy(out + size - 4, "...");
    free(text);
}

/* The first place where `was` and `now` differ, as "evaluation.pairs" in
 * where, and the two values; 0 when they are equal. */
static int first_difference(const cJSON *was, const cJSON *now, char *where, size_t size, char *a, char *b,
                            size_t vsize)
{
    if (cJSON_Compare(was, now, 1)) return 0;
    size_t used = strlen(where);
    if (cJSON_IsObject(was) && cJSON_IsObject(now)) {
        for (int pass = 0; pass < 2; pass++)
            for (const cJSON *kv = (pass ? now : was)->child; kv; kv = kv->next) {
                const cJSON *x = cJSON_GetObjectItemCaseSensitive(was, kv->string);
                const cJSON *y = cJSON_GetObjectItemCaseSensitive(now, kv->string);
                if (cJSON_Compare(x, y, 1)) continue;
                snprintf(where + used, size - used, "%s%s", used ? "." : "", kv->string);
                return first_difference(x, y, where, size, a, b, vsize);
            }
    } else if (cJSON_IsArray(was) && cJSON_IsArray(now) && cJSON_GetArraySize(was) == cJSON_GetArraySize(now)) {
        int i = 0;
        for (const cJSON *x = was->child, *y = now->child; x; x = x->next, y = y->next, i++) {
            if (cJSON_Compare(x, y, 1)) continue;
            snprintf(where + used, size - used, "[%d]", i);
            return first_difference(x, y, where, size, a, b, vsize);
        }
    }
    show(was, a, vsize), show(now, b, vsize);
    return 1;
}

/* Whether the config saved at `path` decides its cells as `cfg` does;
 * else the refusal. */
static int same_cells(const char *path, const tcb_config *cfg, tcb_error *err)
{
    cJSON *was = NULL, *now = cJSON_Parse(cfg->json_text);
    int rc = now ? tcb_json_load(path, &was, err) : tcb_fail(err, TCB_ERR_NOMEM, "out of memory");
    if (rc == TCB_ERR_INPUT)
        tcb_error_prefix(err, "the run directory's record of its config is unreadable (--force replaces it): ");
    if (!rc) {
        cell_settings(was), cell_settings(now);
        char where[256] = "", a[96], b[96];
        if (first_difference(was, now, where, sizeof where, a, b, sizeof a))
            rc = tcb_fail(err, TCB_ERR_INPUT,
                          "%s: the run directory holds the cells of another config than %s (%s: %s there, %s "
                          "here); cells of different settings are not mixed: give this config another --out "
                          "(or 'tcbench run --force' to recompute its cells here and leave the directory to it)",
                          path, cfg->path, where[0] ? where : "the whole config", a, b);
    }
    cJSON_Delete(was);
    cJSON_Delete(now);
    return rc;
}

int tcb_run_dir_claim(const tcb_config *cfg, const char *run_dir, int force, tcb_error *err)
{
    char path[TCB_PATH_MAX], mine[TCB_PATH_MAX];
    int rc = tcb_path_join(path, sizeof path, err, "%s/config.json", run_dir);
    /* The pid in the name makes it a temporary that tcb_remove_stale_temps
     * knows, should this process be killed before it is gone. */
    if (!rc) rc = tcb_path_join(mine, sizeof mine, err, "%s.tmp-%ld-claim", path, (long)getpid());
    if (rc) return rc;
    tcb_remove_stale_temps(run_dir, "config.json.tmp-");
    size_t len = strlen(cfg->json_text);
    char *text = malloc(len + 2);
    if (!text) return tcb_fail(err, TCB_ERR_NOMEM, "out of memory");
    memcpy(text, cfg->json_text, len);
    memcpy(text + len, "\n", 2);
    rc = tcb_write_file_atomic(mine, text, len + 1, err);
    free(text);
    if (rc) {
        tcb_error_prefix(err, "%s: cannot be written: ", path); /* the temporary's name alone says little */
        return rc;
    }
    if (link(mine, path) == 0) {
        unlink(mine);
        return TCB_OK;
    }
    if (errno != EEXIST) rc = tcb_fail(err, TCB_ERR_IO, "%s: cannot create: %s", path, strerror(errno));
    if (!rc && !force) rc = same_cells(path, cfg, err);
    /* The same cells: the record takes this run's roots and paths. */
    if (!rc) return tcb_publish(mine, path, err);
    unlink(mine);
    return rc;
}
