/* The run directory's config.json: the config of the cells it holds.
 *
 * The first run of a directory creates it (link(2) of a complete file:
 * exclusive, so two configs started at once cannot both be first). A later
 * run's config may grow the grid: datasets, sequences, methods and seeds it
 * adds are new cells, and the record becomes the union of both configs
 * (the cells of what it leaves out stay valid and recorded). What would
 * change cells already there is refused, naming the key path and both
 * values: a report would pool them as one method's numbers, and a cell
 * file records its method's params but not its dataset's frames,
 * normalization or pools. A setting every cell depends on (evaluation, a
 * dataset's or a sequence's settings) refuses the whole run; a method's
 * "method" or "params" under a label the directory already holds refuses
 * only that method's cells (the others still run), since its other cells
 * are its numbers under that label: recompute them with --force --only
 * LABEL, or give the changed method a new label. Only what decides a cell
 * is compared, so the same config is still the same run from another
 * machine (other data roots, plug-in paths, cache and splits directories),
 * with other threads, under another name, or with --cell, --shard, --only.
 * A method of a plug-in is recorded with the digest of the plug-in's file
 * (plugin_fnv1a64): a rebuilt plug-in is other code under the same label,
 * refused like changed params (a record made before digests were has none,
 * and takes this run's).
 * --force takes the directory over for the new config (its cells are
 * recomputed as they are selected); another --out keeps both. */
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <unistd.h>

#include "harness/harness_internal.h"
#include "tcb/fsutil.h"
#include "tcb/json.h"
#include "tcb/registry.h"

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

/* A value for a message: whole when short, else the part around `from`
 * (where the two values' texts part), so that cut values still differ. */
static void show(const cJSON *v, size_t from, char *out, size_t size)
{
    char *text = v ? cJSON_PrintUnformatted(v) : NULL;
    const char *t = v ? (text ? text : "?") : "absent";
    size_t len = strlen(t), keep = size - 7, start = 0;
    if (len > keep && from > 16) start = from - 16 < len - keep ? from - 16 : len - keep;
    snprintf(out, size, "%s%.*s%s", start ? "..." : "", (int)keep, t + start, len - start > keep ? "..." : "");
    free(text);
}

/* The first place where `was` and `now` differ, appended to `where`
 * ("evaluation.pairs", "params.command[1]"), and the two values; 0 when
 * they are equal. */
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
    } else if (cJSON_IsArray(was) && cJSON_IsArray(now)) {
        int i = 0;
        for (const cJSON *x = was->child, *y = now->child; x && y; x = x->next, y = y->next, i++) {
            if (cJSON_Compare(x, y, 1)) continue;
            snprintf(where + used, size - used, "[%d]", i);
            return first_difference(x, y, where, size, a, b, vsize);
        }
    }
    char *ta = was ? cJSON_PrintUnformatted(was) : NULL, *tb = now ? cJSON_PrintUnformatted(now) : NULL;
    size_t from = 0;
    while (ta && tb && ta[from] && ta[from] == tb[from]) from++;
    free(ta), free(tb);
    show(was, from, a, vsize), show(now, from, b, vsize);
    return 1;
}

/* The element of `array` whose "name" is `name`, or NULL. */
static cJSON *named(const cJSON *array, const char *name)
{
    for (cJSON *e = cJSON_IsArray(array) ? array->child : NULL; e; e = e->next) {
        const cJSON *n = cJSON_GetObjectItemCaseSensitive(e, "name");
        if (cJSON_IsString(n) && strcmp(n->valuestring, name) == 0) return e;
    }
    return NULL;
}

static const char *name_of(const cJSON *o)
{
    const cJSON *n = cJSON_GetObjectItemCaseSensitive(o, "name");
    return cJSON_IsString(n) ? n->valuestring : "?";
}

static cJSON *item(const cJSON *o, const char *key) { return cJSON_GetObjectItemCaseSensitive(o, key); }

/* The first element of the array o[key]; NULL when there is none (a
 * record edited by hand may lack what a normalized config has). */
static cJSON *first(const cJSON *o, const char *key)
{
    const cJSON *a = item(o, key);
    return cJSON_IsArray(a) ? a->child : NULL;
}

/* first_difference of `was` and `now` less `keys`, under `prefix`. */
static int difference_without(const cJSON *was, const cJSON *now, const char *const *keys, const char *prefix,
                              char *where, size_t size, char *a, char *b, size_t vsize)
{
    cJSON *x = cJSON_Duplicate(was, 1), *y = cJSON_Duplicate(now, 1);
    drop_keys(x, keys), drop_keys(y, keys);
    snprintf(where, size, "%s", prefix);
    int differ = first_difference(x, y, where, size, a, b, vsize);
    cJSON_Delete(x), cJSON_Delete(y);
    return differ;
}

/* The first setting of `now` that would change cells every method has in
 * the directory recorded as `was`: evaluation, a dataset's settings, a
 * sequence's role (datasets and sequences matched by name). */
static int shared_difference(const cJSON *was, const cJSON *now, char *where, size_t size, char *a, char *b,
                             size_t vsize)
{
    static const char *const grown[] = {"seeds", "datasets", "methods", NULL};
    static const char *const sequences[] = {"sequences", NULL}, *const no_keys[] = {NULL};
    if (difference_without(was, now, grown, "", where, size, a, b, vsize)) return 1;
    for (const cJSON *d = first(now, "datasets"); d; d = d->next) {
        const cJSON *w = named(item(was, "datasets"), name_of(d));
        if (!w) continue;
        char prefix[160];
        snprintf(prefix, sizeof prefix, "datasets[%s]", name_of(d));
        if (difference_without(w, d, sequences, prefix, where, size, a, b, vsize)) return 1;
        for (const cJSON *s = first(d, "sequences"); s; s = s->next) {
            const cJSON *ws = named(item(w, "sequences"), name_of(s));
            char at[400];
            snprintf(at, sizeof at, "%s.sequences[%s]", prefix, name_of(s));
            if (ws && difference_without(ws, s, no_keys, at, where, size, a, b, vsize))
                return 1;
        }
    }
    return 0;
}

/* The first difference of the method `now` from the one of its label in
 * `was` (NULL: a method the directory does not know) in what decides its
 * cells: "method" and "params". */
static int method_difference(const cJSON *was, const cJSON *now, char *where, size_t size, char *a, char *b,
                             size_t vsize)
{
    static const char *const unshared[] = {"seeds", "datasets", NULL};
    char prefix[160];
    snprintf(prefix, sizeof prefix, "methods[%s]", name_of(now));
    return was && difference_without(was, now, unshared, prefix, where, size, a, b, vsize);
}

/* Appends to the array `into` the elements of `from` it lacks. */
static void add_missing(cJSON *into, const cJSON *from)
{
    if (!cJSON_IsArray(into)) return;
    for (const cJSON *e = cJSON_IsArray(from) ? from->child : NULL; e; e = e->next) {
        const cJSON *have = into->child;
        while (have && !cJSON_Compare(have, e, 1)) have = have->next;
        if (!have) cJSON_AddItemToArray(into, cJSON_Duplicate(e, 1));
    }
}

/* Appends to `into` copies of the elements of `from` whose name it lacks;
 * for those it has, calls merge (when not NULL) on both. */
static void add_missing_named(cJSON *into, const cJSON *from, void (*merge)(cJSON *, const cJSON *))
{
    for (const cJSON *e = cJSON_IsArray(from) ? from->child : NULL; e; e = e->next) {
        cJSON *have = named(into, name_of(e));
        if (!have) cJSON_AddItemToArray(into, cJSON_Duplicate(e, 1));
        else if (merge) merge(have, e);
    }
}

static void merge_dataset(cJSON *into, const cJSON *from)
{
    add_missing_named(item(into, "sequences"), item(from, "sequences"), NULL);
}

static void replace_item(cJSON *o, const char *key, cJSON *value)
{
    if (!value) return;
    cJSON_DeleteItemFromObjectCaseSensitive(o, key);
    cJSON_AddItemToObject(o, key, value);
}

/* A method's seeds in its config: its own, else the config's. */
static cJSON *method_seeds(const cJSON *m, const cJSON *config)
{
    const cJSON *own = item(m, "seeds");
    return cJSON_Duplicate(own ? own : item(config, "seeds"), 1);
}

/* The union of the configs `was` (the record) and `now`: now's settings
 * and paths, and every dataset, sequence, method and seed of either; a
 * method of both keeps was's "method", "params" and plug-in digest where
 * keep_was[k] (k: its index in now's methods), now's otherwise. */
static cJSON *config_union(const cJSON *was, const cJSON *now, const unsigned char *keep_was)
{
    cJSON *u = cJSON_Duplicate(now, 1), *methods = item(u, "methods");
    int k = 0;
    for (cJSON *m = methods->child; m; m = m->next, k++) {
        const cJSON *w = named(item(was, "methods"), name_of(m));
        /* A method kept as recorded keeps its recorded seeds: this config's
         * are for its other settings. */
        cJSON *seeds = w && keep_was[k] ? method_seeds(w, was) : method_seeds(m, now);
        if (w && !keep_was[k]) add_missing(seeds, item(w, "seeds") ? item(w, "seeds") : item(was, "seeds"));
        replace_item(m, "seeds", seeds);
        if (w && keep_was[k]) {
            replace_item(m, "method", cJSON_Duplicate(item(w, "method"), 1));
            replace_item(m, "params", cJSON_Duplicate(item(w, "params"), 1));
            const cJSON *digest = item(w, "plugin_fnv1a64");
            if (digest) replace_item(m, "plugin_fnv1a64", cJSON_Duplicate(digest, 1));
            else cJSON_DeleteItemFromObjectCaseSensitive(m, "plugin_fnv1a64");
        }
        /* A method that runs on every dataset in either config runs on all. */
        if (w && (!item(w, "datasets") || !item(m, "datasets"))) cJSON_DeleteItemFromObjectCaseSensitive(m, "datasets");
        else if (w) add_missing(item(m, "datasets"), item(w, "datasets"));
    }
    for (const cJSON *w = first(was, "methods"); w; w = w->next)
        if (!named(methods, name_of(w))) {
            cJSON *m = cJSON_Duplicate(w, 1);
            replace_item(m, "seeds", method_seeds(w, was));
            cJSON_AddItemToArray(methods, m);
        }
    add_missing(item(u, "seeds"), item(was, "seeds"));
    add_missing_named(item(u, "datasets"), item(was, "datasets"), merge_dataset);
    /* Seeds are spelled out only where they are a method's own (config_dump.c). */
    for (cJSON *m = methods->child; m; m = m->next)
        if (cJSON_Compare(item(m, "seeds"), item(u, "seeds"), 1)) cJSON_DeleteItemFromObjectCaseSensitive(m, "seeds");
    return u;
}

/* What a claim is for and what it found. */
typedef struct claim {
    const tcb_config *cfg;
    char path[TCB_PATH_MAX];     /* <run>/config.json */
    const tcb_run_opts *opts;    /* force, only_method */
    int for_score;               /* `tcbench score`: its cell is no config method's */
    unsigned char *refused;      /* [cfg->n_methods]: 1 where this run leaves the method's cells alone */
    tcb_error *refusal;          /* why, TCB_OK when nothing was refused */
} claim;

/* This run's config as the directory records it: the normalized config,
 * each plug-in method with its file's digest. NULL when out of memory. */
static cJSON *record_of(const tcb_config *cfg)
{
    cJSON *r = cJSON_Parse(cfg->json_text);
    int k = 0;
    for (cJSON *m = r ? first(r, "methods") : NULL; m && k < cfg->n_methods; m = m->next, k++) {
        const tcb_method_ops *ops = tcb_registry_find(cfg->methods[k].method);
        const char *digest = ops ? tcb_registry_digest(ops) : NULL;
        if (!digest) continue;
        /* the build loaded now, over what a config copied from a record says */
        cJSON_DeleteItemFromObjectCaseSensitive(m, "plugin_fnv1a64");
        if (!cJSON_AddStringToObject(m, "plugin_fnv1a64", digest)) {
            cJSON_Delete(r);
            return NULL;
        }
    }
    return r;
}

/* The record's text, as config.json holds it. malloc'ed; NULL when out of
 * memory. */
static char *record_text(const tcb_config *cfg)
{
    cJSON *r = record_of(cfg);
    char *text = r ? cJSON_Print(r) : NULL;
    cJSON_Delete(r);
    return text;
}

/* The refusal of a setting every cell depends on, with the way out that
 * fits the command. */
static int refuse_all(const claim *c, const char *where, const char *a, const char *b, tcb_error *err)
{
    char hint[TCB_PATH_MAX + 128];
    if (!c->for_score)
        snprintf(hint, sizeof hint, "or 'tcbench run --force' to recompute its cells here and leave the directory to it");
    else
        snprintf(hint, sizeof hint, "or score against the directory's own config: 'tcbench score %s …'", c->path);
    return tcb_fail(err, TCB_ERR_INPUT,
                    "%s: the run directory holds the cells of another config than %s (%s: %s there, %s here); "
                    "cells of different settings are not mixed: give this config another --out (%s)",
                    c->path, c->cfg->path, where[0] ? where : "the whole config", a, b, hint);
}

/* Appends method k's difference to the refusal and marks it refused. */
static void refuse_method(const claim *c, int k, const char *where, const char *a, const char *b)
{
    tcb_error *r = c->refusal;
    size_t used = strlen(r->msg);
    snprintf(r->msg + used, sizeof r->msg - used, "%s%s: %s there, %s here", used ? "; " : "", where, a, b);
    r->code = TCB_ERR_INPUT;
    c->refused[k] = 1;
}

/* The refusal's whole message: what differs, what ran, the way out. */
static void finish_refusal(const claim *c)
{
    tcb_error *r = c->refusal;
    if (!r->code) return;
    char labels[1024] = "";
    int n = 0;
    for (int k = 0; k < c->cfg->n_methods; k++)
        if (c->refused[k]) {
            size_t used = strlen(labels);
            snprintf(labels + used, sizeof labels - used, "%s%s", n++ ? ", " : "", c->cfg->methods[k].label);
        }
    char what[TCB_ERRMSG_MAX];
    snprintf(what, sizeof what, "%s", r->msg);
    if (n == 1)
        tcb_fail(r, TCB_ERR_INPUT,
                 "%s: the run directory holds %s's cells with other settings (%s), so this run left them alone; "
                 "recompute them here with 'tcbench run %s --force --only %s', or give the changed method a new "
                 "label",
                 c->path, labels, what, c->cfg->path, labels);
    else
        tcb_fail(r, TCB_ERR_INPUT,
                 "%s: the run directory holds the cells of %s with other settings (%s), so this run left them "
                 "alone; recompute them here with 'tcbench run %s --force --only LABEL' for each of %s, or give "
                 "the changed methods new labels",
                 c->path, labels, what, c->cfg->path, labels);
}

/* Compares the record `was` with this run's config `now`: a refusal of
 * the whole run in err, or the methods refused in c; *keep_was[k]: the
 * union keeps the record's method for now's method k. */
static int compare_configs(const claim *c, const cJSON *was, const cJSON *now, unsigned char *keep_was,
                           tcb_error *err)
{
    char where[512] = "", a[96], b[96];
    cJSON *x = cJSON_Duplicate(was, 1), *y = cJSON_Duplicate(now, 1);
    cell_settings(x), cell_settings(y);
    int rc = shared_difference(x, y, where, sizeof where, a, b, sizeof a) ? refuse_all(c, where, a, b, err) : TCB_OK;
    int k = 0;
    for (cJSON *m = first(y, "methods"); m && !rc; m = m->next, k++) {
        cJSON *w = named(item(x, "methods"), name_of(m));
        /* A digest compares only with a digest: a record made before them
         * has none, and a listing that loads no plug-in knows none. */
        if (!w || !item(w, "plugin_fnv1a64") || !item(m, "plugin_fnv1a64")) {
            cJSON_DeleteItemFromObjectCaseSensitive(m, "plugin_fnv1a64");
            if (w) cJSON_DeleteItemFromObjectCaseSensitive(w, "plugin_fnv1a64");
        }
        if (!method_difference(w, m, where, sizeof where, a, b, sizeof a)) continue;
        /* --force recomputes what it selects; the record keeps the rest,
         * and a method this run does not select is not its to refuse. */
        int selected = tcb_run_selected(c->opts, &c->cfg->methods[k]), forced = c->opts->force && selected;
        keep_was[k] = !forced;
        if (!c->for_score && selected && !forced) refuse_method(c, k, where, a, b);
    }
    cJSON_Delete(x), cJSON_Delete(y);
    finish_refusal(c);
    return rc;
}

/* The record for a directory that has one: the union of it and this run's
 * config, or this config where --force takes the directory over. */
static int grow_record(const claim *c, char **text, tcb_error *err)
{
    cJSON *was = NULL, *now = record_of(c->cfg);
    int rc = now ? tcb_json_load(c->path, &was, err) : tcb_fail(err, TCB_ERR_NOMEM, "out of memory");
    if (rc == TCB_ERR_INPUT)
        tcb_error_prefix(err, "the run directory's record of its config is unreadable (--force replaces it): ");
    unsigned char *keep_was = rc ? NULL : calloc((size_t)c->cfg->n_methods + 1, 1);
    if (!rc && !keep_was) rc = tcb_fail(err, TCB_ERR_NOMEM, "out of memory");
    if (!rc) rc = compare_configs(c, was, now, keep_was, err);
    int take_over = c->opts->force && rc == TCB_ERR_INPUT;
    if (take_over) tcb_error_clear(err), rc = TCB_OK;
    cJSON *u = rc ? NULL : take_over ? cJSON_Duplicate(now, 1) : config_union(was, now, keep_was);
    *text = u ? cJSON_Print(u) : NULL;
    if (!rc && !*text) rc = tcb_fail(err, TCB_ERR_NOMEM, "out of memory");
    cJSON_Delete(u), cJSON_Delete(was), cJSON_Delete(now);
    free(keep_was);
    return rc;
}

/* Writes `text` and a newline to `path` through a temporary; errors name
 * `shown` (a temporary's name alone says little). */
static int write_record(const char *path, const char *shown, const char *text, tcb_error *err)
{
    size_t len = strlen(text);
    char *line = malloc(len + 2);
    if (!line) return tcb_fail(err, TCB_ERR_NOMEM, "out of memory");
    memcpy(line, text, len);
    memcpy(line + len, "\n", 2);
    int rc = tcb_write_file_atomic(path, line, len + 1, err);
    free(line);
    if (rc) tcb_error_prefix(err, "%s: cannot be written: ", shown);
    return rc;
}

/* Creates the record (link(2): exclusive) or grows it, under a lock on
 * the directory so that two configs growing it at once both land in it. */
static int claim_dir(const claim *c, const char *run_dir, tcb_error *err)
{
    char mine[TCB_PATH_MAX];
    /* The pid in the name makes it a temporary that tcb_remove_stale_temps
     * knows, should this process be killed before it is gone. */
    int rc = tcb_path_join(mine, sizeof mine, err, "%s.tmp-%ld-claim", c->path, (long)getpid());
    if (rc) return rc;
    tcb_remove_stale_temps(run_dir, "config.json.tmp-");
    char *record = record_text(c->cfg);
    rc = record ? write_record(mine, c->path, record, err) : tcb_fail(err, TCB_ERR_NOMEM, "out of memory");
    free(record);
    if (rc) return rc;
    if (link(mine, c->path) == 0) return unlink(mine), TCB_OK;
    unlink(mine);
    if (errno != EEXIST) return tcb_fail(err, TCB_ERR_IO, "%s: cannot create: %s", c->path, strerror(errno));
    int dir = open(run_dir, O_RDONLY | O_DIRECTORY);
    if (dir < 0 || flock(dir, LOCK_EX) != 0)
        rc = tcb_fail(err, TCB_ERR_IO, "%s: cannot lock: %s", run_dir, strerror(errno));
    char *text = NULL;
    if (!rc) rc = grow_record(c, &text, err);
    if (!rc) rc = write_record(c->path, c->path, text, err);
    free(text);
    if (dir >= 0) close(dir); /* and the lock with it */
    return rc;
}

static int claim_for(claim *c, const char *run_dir, tcb_error *err)
{
    int rc = tcb_path_join(c->path, sizeof c->path, err, "%s/config.json", run_dir);
    return rc ? rc : claim_dir(c, run_dir, err);
}

int tcb_run_dir_claim(const tcb_config *cfg, const char *run_dir, int force, tcb_error *err)
{
    tcb_run_opts opts = {.force = force};
    tcb_error refusal = {0};
    claim c = {.cfg = cfg, .opts = &opts, .for_score = 1, .refusal = &refusal};
    return claim_for(&c, run_dir, err);
}

int tcb_run_dir_refusals(const tcb_config *cfg, const char *run_dir, const tcb_run_opts *opts,
                         unsigned char *refused, tcb_error *err)
{
    memset(refused, 0, (size_t)cfg->n_methods);
    tcb_error refusal = {0}, whole = {0};
    claim c = {.cfg = cfg, .opts = opts, .refused = refused, .refusal = &refusal};
    int rc = tcb_path_join(c.path, sizeof c.path, err, "%s/config.json", run_dir);
    if (rc || !tcb_is_file(c.path)) return rc;
    cJSON *was = NULL, *now = record_of(cfg);
    unsigned char *keep_was = calloc((size_t)cfg->n_methods + 1, 1);
    /* An unreadable record, or a config refused as a whole, is the run's to
     * say: the listing shows the cells as they are. */
    if (now && keep_was && tcb_json_load(c.path, &was, &whole) == TCB_OK) compare_configs(&c, was, now, keep_was, &whole);
    else if (!now || !keep_was) rc = tcb_fail(err, TCB_ERR_NOMEM, "out of memory");
    cJSON_Delete(was), cJSON_Delete(now);
    free(keep_was);
    return rc;
}

int tcb_run_dir_claim_methods(const tcb_config *cfg, const char *run_dir, const tcb_run_opts *opts,
                              unsigned char *refused, tcb_error *refusal, tcb_error *err)
{
    memset(refused, 0, (size_t)cfg->n_methods);
    tcb_error_clear(refusal);
    claim c = {.cfg = cfg, .opts = opts, .refused = refused, .refusal = refusal};
    return claim_for(&c, run_dir, err);
}
