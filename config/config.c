/* The run configuration: a strict JSON reader (every key known, every value
 * checked, errors naming the key path) and the normalized JSON text with all
 * defaults filled in, which the runner stores beside the results. */
#include "tcb/config.h"

#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "config/config_internal.h"
#include "tcb/align.h"
#include "tcb/json.h"
#include "tcb/metrics.h"
#include "tcb/synth.h"

#define WHERE_MAX 512

static const char *const top_keys[] = {"name", "output", "splits_dir", "cache_dir", "plugins",
                                       "seeds", "threads", "evaluation", "datasets", "methods",
                                       "reference", NULL};
static const char *const reference_keys[] = {"source", "tables", NULL};
static const char *const eval_keys[] = {"pairs", "split_seed", "pool_size", "pool_seed", "input_points",
                                        "protocol", "clips", "fit", "input_normals", "recon_frame",
                                        "surface_samples", NULL};
/* Indexed by the bit's position: TCB_PROTOCOL_PAIRS, TCB_PROTOCOL_CLIPS. */
const char *const tcb_config_protocol_names[] = {"pairs", "clips", NULL};
static const char *const synthetic_keys[] = {"name", "source", "seed", "frames", "normalization",
                                             "align_rotation", "align_samples", "sampling", "sequences", NULL};
static const char *const objdir_keys[] = {"name", "source", "root", "optional", "normalization",
                                          "align_rotation", "align_samples", "sampling", "sequences", NULL};
/* No rotation alignment: it chains each frame to the previous one, which
 * across the subjects' blocks would be meaningless, and DFAUST has none. */
static const char *const pcl_seq_keys[] = {"name", "source", "root", "optional", "normalization",
                                           "sampling", "points", "sequences", NULL};
static const char *const dfaust_keys[] = {"name", "source", "root", "optional", "normalization",
                                          "sampling", "subjects", "sequences", NULL};
static const char *const sequence_keys[] = {"name", "role", "clip_starts", "clip_of", "start", NULL};
static const char *const method_keys[] = {"name", "method", "params", "seeds", "datasets", "plugin_fnv1a64", NULL};

const char *const tcb_config_source_names[] = {"synthetic", "objdir", "dfaust", "clipdir", "pcl_seq", NULL};
const char *const tcb_config_norm_names[] = {"none", "first_frame", "per_frame", "clip_bbox", "first_frame_diag", NULL};
const char *const tcb_config_fit_names[] = {"sequence", "per_clip", NULL};
const char *const tcb_config_input_normals_names[] = {"none", "gt", "estimated", NULL};
const char *const tcb_config_sampling_names[] = {"without_replacement", "with_replacement", NULL};

/* The json helpers join `where` and a key with '.', which at the top level
 * would read "quick.json:.threads"; turn that into "quick.json: threads". */
static int fix_top(int rc, const char *origin, tcb_error *err)
{
    size_t n = strlen(origin);
    if (rc && err && strncmp(err->msg, origin, n) == 0 && err->msg[n] == ':' &&
        err->msg[n + 1] == '.')
        err->msg[n + 1] = ' ';
    return rc;
}

/* Names become path components of the run directory: keep them portable. */
static int check_name(const char *name, size_t cap, const char *where, const char *key,
                      tcb_error *err)
{
    size_t len = strlen(name);
    if (len == 0 || len >= cap)
        return tcb_fail(err, TCB_ERR_INPUT, "%s.%s: must be 1 to %zu characters", where, key,
                        cap - 1);
    if (name[0] == '.')
        return tcb_fail(err, TCB_ERR_INPUT, "%s.%s: '%s' must not start with '.'", where, key,
                        name);
    for (const char *p = name; *p; p++) {
        int ok = (*p >= 'a' && *p <= 'z') || (*p >= 'A' && *p <= 'Z') ||
                 (*p >= '0' && *p <= '9') || *p == '_' || *p == '-' || *p == '.';
        if (!ok)
            return tcb_fail(err, TCB_ERR_INPUT,
                            "%s.%s: '%s' may only contain letters, digits, '_', '-' and '.'",
                            where, key, name);
    }
    return TCB_OK;
}

static int copy_str(char *dst, size_t cap, const char *src, const char *where, const char *key,
                    tcb_error *err)
{
    if (strlen(src) >= cap)
        return tcb_fail(err, TCB_ERR_INPUT, "%s.%s: longer than %zu characters", where, key,
                        cap - 1);
    memcpy(dst, src, strlen(src) + 1);
    return TCB_OK;
}

/* obj[key] as an array; *out = NULL when absent and not required. */
static int get_array(const cJSON *obj, const char *key, const char *where, int required,
                     const cJSON **out, tcb_error *err)
{
    *out = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!*out && required)
        return tcb_fail(err, TCB_ERR_INPUT, "%s.%s: required key is missing", where, key);
    if (*out && !cJSON_IsArray(*out))
        return tcb_fail(err, TCB_ERR_INPUT, "%s.%s: expected an array", where, key);
    return TCB_OK;
}

/* A synthetic dataset's sequences are the generator's. */
static int check_synthetic(const char *name, const char *where, const char *key, tcb_error *err)
{
    for (int k = 0; k < tcb_synth_count(); k++)
        if (strcmp(tcb_synth_name(k), name) == 0) return TCB_OK;
    char list[512] = "";
    for (int k = 0; k < tcb_synth_count(); k++) {
        size_t used = strlen(list);
        snprintf(list + used, sizeof list - used, "%s%s", k ? ", " : "", tcb_synth_name(k));
    }
    return tcb_fail(err, TCB_ERR_INPUT, "%s.%s: unknown synthetic sequence '%s' (expected %s)", where, key, name,
                    list);
}

/* How many sequences entry o stands for: its "clip_starts", else one. */
static int entry_count(const cJSON *o)
{
    const cJSON *starts = cJSON_IsObject(o) ? cJSON_GetObjectItemCaseSensitive(o, "clip_starts") : NULL;
    return cJSON_IsArray(starts) && cJSON_GetArraySize(starts) > 0 ? cJSON_GetArraySize(starts) : 1;
}

/* "clip_starts": the entry's clips, each a sequence "<name>_<start as %04d>". */
static int expand_clip_starts(const cJSON *starts, const char *where, const tcb_sequence_spec *base,
                              tcb_sequence_spec *out, tcb_error *err)
{
    int n = cJSON_GetArraySize(starts);
    if (!cJSON_IsArray(starts) || n == 0)
        return tcb_fail(err, TCB_ERR_INPUT, "%s.clip_starts: expected a non-empty list of first frames", where);
    for (int k = 0; k < n; k++) {
        const cJSON *v = cJSON_GetArrayItem(starts, k);
        double x = cJSON_IsNumber(v) ? v->valuedouble : -1;
        if (x < 0 || x > 100000000 || x != floor(x))
            return tcb_fail(err, TCB_ERR_INPUT, "%s.clip_starts[%d]: expected a frame number >= 0", where, k);
        out[k] = *base;
        snprintf(out[k].clip_of, sizeof out[k].clip_of, "%s", base->name);
        out[k].start = (int)x;
        int len = snprintf(out[k].name, sizeof out[k].name, "%s_%04d", base->name, out[k].start);
        if (len >= (int)sizeof out[k].name)
            return tcb_fail(err, TCB_ERR_INPUT, "%s.clip_starts[%d]: the clip's name %s_%04d is too long", where, k,
                            base->name, out[k].start);
    }
    return TCB_OK;
}

/* "clip_of" and "start": one clip, as a run directory records it. */
static int parse_clip_of(const cJSON *o, const char *where, tcb_sequence_spec *s, tcb_error *err)
{
    const char *of;
    long long start;
    int rc = tcb_json_str(o, "clip_of", where, 1, NULL, &of, err);
    if (!rc) rc = check_name(of, sizeof s->clip_of, where, "clip_of", err);
    if (!rc) rc = tcb_json_int(o, "start", where, 1, 0, 0, 100000000, &start, err);
    if (rc) return rc;
    snprintf(s->clip_of, sizeof s->clip_of, "%s", of);
    s->start = (int)start;
    return TCB_OK;
}

/* One entry of "sequences" into out[0 .. entry_count(o)). */
static int parse_sequence(const cJSON *o, const char *where, const tcb_dataset_spec *d, int per_clip,
                          tcb_sequence_spec *out, tcb_error *err)
{
    const char *name, *role;
    int rc = tcb_json_expect_keys(o, where, sequence_keys, err);
    if (!rc) rc = tcb_json_str(o, "name", where, 1, NULL, &name, err);
    if (!rc) rc = check_name(name, sizeof out->name, where, "name", err);
    if (!rc) rc = tcb_json_str(o, "role", where, 1, NULL, &role, err);
    if (rc) return rc;
    if (tcb_role_parse(role, &out->role) != 0)
        return tcb_fail(err, TCB_ERR_INPUT,
                        "%s.role: unknown role '%s' (expected train, validation or test)", where,
                        role);
    snprintf(out->name, sizeof out->name, "%s", name);
    const cJSON *starts = cJSON_GetObjectItemCaseSensitive(o, "clip_starts");
    int clip_of = cJSON_HasObjectItem(o, "clip_of") || cJSON_HasObjectItem(o, "start");
    const char *clip_key = starts ? "clip_starts" : clip_of ? "clip_of" : NULL;
    if (clip_key && !per_clip)
        return tcb_fail(err, TCB_ERR_INPUT, "%s.%s: clips of a sequence are fitted on their own only under "
                        "\"evaluation\": {\"fit\": \"per_clip\"}", where, clip_key);
    if (starts && clip_of)
        return tcb_fail(err, TCB_ERR_INPUT, "%s: give either clip_starts or clip_of and start, not both", where);
    if (starts) {
        tcb_sequence_spec base = *out;
        rc = expand_clip_starts(starts, where, &base, out, err);
    }
    if (clip_of) rc = parse_clip_of(o, where, out, err);
    if (rc || d->source != TCB_SOURCE_SYNTHETIC) return rc;
    return clip_of ? check_synthetic(out->clip_of, where, "clip_of", err)
                   : check_synthetic(name, where, "name", err);
}

static int parse_sequences(const cJSON *o, const char *where, int per_clip, tcb_dataset_spec *d,
                           tcb_error *err)
{
    const cJSON *arr;
    int rc = get_array(o, "sequences", where, 1, &arr, err);
    if (rc) return rc;
    int n = cJSON_GetArraySize(arr), total = 0;
    if (n == 0)
        return tcb_fail(err, TCB_ERR_INPUT, "%s.sequences: must list at least one sequence",
                        where);
    for (int k = 0; k < n; k++) total += entry_count(cJSON_GetArrayItem(arr, k));
    d->sequences = calloc((size_t)total, sizeof *d->sequences);
    int *entry_of = malloc((size_t)total * sizeof *entry_of); /* each sequence's entry, for messages */
    if (!d->sequences || !entry_of) {
        free(entry_of);
        return tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", where);
    }
    char sw[WHERE_MAX + 32]; /* where + ".sequences[k]" */
    for (int k = 0; k < n && !rc; k++) {
        const cJSON *e = cJSON_GetArrayItem(arr, k);
        snprintf(sw, sizeof sw, "%s.sequences[%d]", where, k);
        tcb_sequence_spec *first = &d->sequences[d->n_sequences];
        rc = parse_sequence(e, sw, d, per_clip, first, err);
        for (int c = 0; !rc && c < entry_count(e); c++, d->n_sequences++) {
            entry_of[d->n_sequences] = k;
            for (int m = 0; !rc && m < d->n_sequences; m++)
                if (strcmp(d->sequences[m].name, first[c].name) == 0)
                    rc = tcb_fail(err, TCB_ERR_INPUT, "%s.%s: duplicate sequence '%s' (also %s.sequences[%d])", sw,
                                  first[c].clip_of[0] ? "clip_starts" : "name", first[c].name, where, entry_of[m]);
        }
    }
    free(entry_of);
    return rc;
}

/* dfaust "subjects": distinct ids, each a valid name (they key datasets). */
static int parse_subjects(const cJSON *o, const char *where, tcb_dataset_spec *d, tcb_error *err)
{
    const cJSON *arr;
    int rc = get_array(o, "subjects", where, 0, &arr, err);
    if (rc || !arr) return rc;
    int n = cJSON_GetArraySize(arr);
    if (n == 0) return tcb_fail(err, TCB_ERR_INPUT, "%s.subjects: must list at least one subject", where);
    if (!(d->subjects = calloc((size_t)n, sizeof *d->subjects)))
        return tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", where);
    char key[32];
    for (int k = 0; k < n; k++) {
        const cJSON *s = cJSON_GetArrayItem(arr, k);
        snprintf(key, sizeof key, "subjects[%d]", k);
        if (!cJSON_IsString(s))
            return tcb_fail(err, TCB_ERR_INPUT, "%s.%s: expected a subject id string", where, key);
        rc = check_name(s->valuestring, TCB_BLOCK_NAME_MAX, where, key, err);
        if (rc) return rc;
        for (int m = 0; m < k; m++)
            if (strcmp(d->subjects[m], s->valuestring) == 0)
                return tcb_fail(err, TCB_ERR_INPUT, "%s.%s: duplicate subject '%s'", where, key,
                                s->valuestring);
        if (!(d->subjects[k] = strdup(s->valuestring)))
            return tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", where);
        d->n_subjects = k + 1;
    }
    return TCB_OK;
}

static int parse_dataset(const cJSON *o, const char *where, int per_clip, tcb_dataset_spec *d, tcb_error *err)
{
    const char *name, *root;
    int source, norm, sampling;
    long long seed, frames;
    int rc = tcb_json_expect_object(o, where, err);
    if (!rc) rc = tcb_json_enum(o, "source", where, 1, 0, tcb_config_source_names, &source, err);
    if (rc) return rc;
    d->source = (tcb_source)source;
    int synthetic = d->source == TCB_SOURCE_SYNTHETIC, dfaust = d->source == TCB_SOURCE_DFAUST;
    int pcl = d->source == TCB_SOURCE_PCL_SEQ;
    rc = tcb_json_expect_keys(o, where,
                              synthetic ? synthetic_keys : dfaust ? dfaust_keys : pcl ? pcl_seq_keys : objdir_keys, err);
    if (!rc) rc = tcb_json_str(o, "name", where, 1, NULL, &name, err);
    if (!rc) rc = check_name(name, sizeof d->name, where, "name", err);
    if (!rc) rc = tcb_json_int(o, "seed", where, 0, 0, 0, LLONG_MAX, &seed, err);
    if (!rc) rc = tcb_json_int(o, "frames", where, 0, 0, 0, 100000, &frames, err);
    if (!rc) rc = tcb_json_str(o, "root", where, 0, "", &root, err);
    if (!rc) rc = copy_str(d->root, sizeof d->root, root, where, "root", err);
    if (!rc) rc = tcb_json_bool(o, "optional", where, 0, 0, &d->optional, err);
    if (!rc)
        rc = tcb_json_enum(o, "normalization", where, 0,
                           dfaust || pcl || d->source == TCB_SOURCE_CLIPDIR ? TCB_NORM_NONE : TCB_NORM_FIRST_FRAME,
                           tcb_config_norm_names, &norm, err);
    long long align_samples;
    if (!rc) rc = tcb_json_bool(o, "align_rotation", where, 0, 0, &d->align_rotation, err);
    if (!rc) rc = tcb_json_int(o, "align_samples", where, 0, TCB_ALIGN_DEFAULT_SAMPLES, 1, 10000000, &align_samples, err);
    if (!rc) rc = tcb_json_enum(o, "sampling", where, 0, dfaust, tcb_config_sampling_names, &sampling, err);
    long long points;
    if (!rc) rc = tcb_json_int(o, "points", where, 0, TCB_PCL_SEQ_DEFAULT_POINTS, 0, 10000000, &points, err);
    if (!rc) rc = parse_subjects(o, where, d, err);
    if (rc) return rc;
    snprintf(d->name, sizeof d->name, "%s", name);
    d->seed = (uint64_t)seed;
    d->frames = (int)frames;
    d->norm = (tcb_normalization)norm;
    d->with_replacement = sampling == 1;
    d->points = pcl ? (int)points : 0;
    d->align_samples = d->align_rotation ? (int)align_samples : 0;
    return parse_sequences(o, where, per_clip, d, err);
}

/* The distinct non-negative seeds of `arr`; `where` names the list
 * ("t.json: seeds", "t.json: methods[1].seeds"). */
static int parse_seed_list(const cJSON *arr, const char *where, int **seeds, int *n_seeds,
                           tcb_error *err)
{
    int n = cJSON_GetArraySize(arr);
    if (n == 0) return tcb_fail(err, TCB_ERR_INPUT, "%s: must list at least one seed", where);
    *seeds = calloc((size_t)n, sizeof **seeds);
    if (!*seeds) return tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", where);
    *n_seeds = n;
    for (int k = 0; k < n; k++) {
        const cJSON *s = cJSON_GetArrayItem(arr, k);
        double v = cJSON_IsNumber(s) ? s->valuedouble : -1;
        if (v < 0 || v > INT_MAX || v != floor(v))
            return tcb_fail(err, TCB_ERR_INPUT,
                            "%s[%d]: expected a non-negative integer below 2^31", where, k);
        (*seeds)[k] = (int)v;
        for (int m = 0; m < k; m++)
            if ((*seeds)[m] == (*seeds)[k])
                return tcb_fail(err, TCB_ERR_INPUT, "%s[%d]: duplicate seed %d", where, k,
                                (*seeds)[k]);
    }
    return TCB_OK;
}

/* The method's own "seeds", else a copy of the config's. */
static int parse_method_seeds(const cJSON *o, const char *where, const tcb_config *c,
                              tcb_method_spec *m, tcb_error *err)
{
    const cJSON *arr;
    int rc = get_array(o, "seeds", where, 0, &arr, err);
    if (rc) return rc;
    if (arr) {
        char w[WHERE_MAX + 8]; /* where + ".seeds" */
        snprintf(w, sizeof w, "%s.seeds", where);
        return parse_seed_list(arr, w, &m->seeds, &m->n_seeds, err);
    }
    m->seeds = malloc((size_t)c->n_seeds * sizeof *m->seeds);
    if (!m->seeds) return tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", where);
    memcpy(m->seeds, c->seeds, (size_t)c->n_seeds * sizeof *m->seeds);
    m->n_seeds = c->n_seeds;
    return TCB_OK;
}

/* "datasets": names of the config's datasets, each once. */
static int parse_method_datasets(const cJSON *o, const char *where, const tcb_config *c, tcb_method_spec *m,
                                 tcb_error *err)
{
    const cJSON *arr;
    int rc = get_array(o, "datasets", where, 0, &arr, err);
    if (rc || !arr) return rc;
    int n = cJSON_GetArraySize(arr);
    if (n == 0) return tcb_fail(err, TCB_ERR_INPUT, "%s.datasets: must list at least one dataset", where);
    m->only_on = calloc((size_t)n, sizeof *m->only_on);
    if (!m->only_on) return tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", where);
    for (int k = 0; k < n; k++) {
        const cJSON *d = cJSON_GetArrayItem(arr, k);
        int known = 0;
        for (int j = 0; cJSON_IsString(d) && j < c->n_datasets; j++)
            known |= strcmp(c->datasets[j].name, d->valuestring) == 0;
        if (!known)
            return tcb_fail(err, TCB_ERR_INPUT, "%s.datasets[%d]: expected the name of one of the config's datasets",
                            where, k);
        if (tcb_method_runs_on(m, d->valuestring) && m->n_only_on)
            return tcb_fail(err, TCB_ERR_INPUT, "%s.datasets[%d]: duplicate dataset '%s'", where, k, d->valuestring);
        snprintf(m->only_on[k], sizeof m->only_on[k], "%s", d->valuestring);
        m->n_only_on = k + 1;
    }
    return TCB_OK;
}

int tcb_method_runs_on(const tcb_method_spec *m, const char *dataset)
{
    for (int k = 0; k < m->n_only_on; k++)
        if (strcmp(m->only_on[k], dataset) == 0) return 1;
    return m->n_only_on == 0;
}

int tcb_config_find_sequence(const tcb_config *c, const char *dataset, const char *sequence,
                             const tcb_dataset_spec **d, const tcb_sequence_spec **s, tcb_error *err)
{
    *d = NULL, *s = NULL;
    for (int k = 0; k < c->n_datasets && !*d; k++)
        if (!strcmp(c->datasets[k].name, dataset)) *d = &c->datasets[k];
    if (!*d) return tcb_fail(err, TCB_ERR_INPUT, "%s has no dataset named '%s'", c->path, dataset);
    for (int k = 0; k < (*d)->n_sequences && !*s; k++)
        if (!strcmp((*d)->sequences[k].name, sequence)) *s = &(*d)->sequences[k];
    if (!*s)
        return tcb_fail(err, TCB_ERR_INPUT, "dataset %s of %s has no sequence named '%s'", dataset, c->path,
                        sequence);
    return TCB_OK;
}

/* "plugin_fnv1a64": 16 hex digits, what a run directory's record says of a
 * plug-in method (harness/run_config.c); optional. */
static int parse_plugin_digest(const cJSON *o, const char *where, tcb_method_spec *m, tcb_error *err)
{
    const char *digest;
    int rc = tcb_json_str(o, "plugin_fnv1a64", where, 0, "", &digest, err);
    if (rc || !digest[0]) return rc;
    if (strlen(digest) != 16 || strspn(digest, "0123456789abcdef") != 16)
        return tcb_fail(err, TCB_ERR_INPUT, "%s.plugin_fnv1a64: expected 16 hex digits, got \"%s\"", where, digest);
    memcpy(m->plugin_digest, digest, sizeof m->plugin_digest);
    return TCB_OK;
}

static int parse_method(const cJSON *o, const char *where, const tcb_config *c,
                        tcb_method_spec *m, tcb_error *err)
{
    const char *label, *impl;
    int rc = tcb_json_expect_keys(o, where, method_keys, err);
    if (!rc) rc = tcb_json_str(o, "name", where, 1, NULL, &label, err);
    if (!rc) rc = check_name(label, sizeof m->label, where, "name", err);
    if (!rc) rc = tcb_json_str(o, "method", where, 0, label, &impl, err);
    if (!rc) rc = copy_str(m->method, sizeof m->method, impl, where, "method", err);
    if (rc) return rc;
    snprintf(m->label, sizeof m->label, "%s", label);
    if (!m->method[0]) return tcb_fail(err, TCB_ERR_INPUT, "%s.method: must not be empty", where);
    const cJSON *params = cJSON_GetObjectItemCaseSensitive(o, "params");
    if (params && !cJSON_IsObject(params))
        return tcb_fail(err, TCB_ERR_INPUT, "%s.params: expected an object", where);
    /* The method itself validates the keys when it is created. */
    m->params_json = params ? cJSON_PrintUnformatted(params) : strdup("{}");
    if (!m->params_json) return tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", where);
    rc = parse_method_seeds(o, where, c, m, err);
    if (!rc) rc = parse_plugin_digest(o, where, m, err);
    return rc ? rc : parse_method_datasets(o, where, c, m, err);
}

static int parse_datasets(const cJSON *root, const char *origin, tcb_config *c, tcb_error *err)
{
    char top[WHERE_MAX], w[WHERE_MAX];
    snprintf(top, sizeof top, "%s:", origin);
    const cJSON *arr;
    int rc = fix_top(get_array(root, "datasets", top, 1, &arr, err), origin, err);
    if (rc) return rc;
    int n = cJSON_GetArraySize(arr);
    if (n == 0)
        return tcb_fail(err, TCB_ERR_INPUT, "%s: datasets: must list at least one dataset",
                        origin);
    c->datasets = calloc((size_t)n, sizeof *c->datasets);
    if (!c->datasets) return tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", origin);
    for (int k = 0; k < n; k++) {
        snprintf(w, sizeof w, "%s: datasets[%d]", origin, k);
        rc = parse_dataset(cJSON_GetArrayItem(arr, k), w, c->fit_per_clip, &c->datasets[k], err);
        c->n_datasets = k + 1; /* so tcb_config_free releases its sequences */
        if (rc) return rc;
        for (int m = 0; m < k; m++)
            if (strcmp(c->datasets[m].name, c->datasets[k].name) == 0)
                return tcb_fail(err, TCB_ERR_INPUT,
                                "%s.name: duplicate dataset '%s' (also datasets[%d])", w,
                                c->datasets[k].name, m);
    }
    return TCB_OK;
}

static int parse_methods(const cJSON *root, const char *origin, tcb_config *c, tcb_error *err)
{
    char top[WHERE_MAX], w[WHERE_MAX];
    snprintf(top, sizeof top, "%s:", origin);
    const cJSON *arr;
    int rc = fix_top(get_array(root, "methods", top, 1, &arr, err), origin, err);
    if (rc) return rc;
    int n = cJSON_GetArraySize(arr);
    if (n == 0)
        return tcb_fail(err, TCB_ERR_INPUT, "%s: methods: must list at least one method", origin);
    c->methods = calloc((size_t)n, sizeof *c->methods);
    if (!c->methods) return tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", origin);
    for (int k = 0; k < n; k++) {
        snprintf(w, sizeof w, "%s: methods[%d]", origin, k);
        rc = parse_method(cJSON_GetArrayItem(arr, k), w, c, &c->methods[k], err);
        c->n_methods = k + 1;
        if (rc) return rc;
        for (int m = 0; m < k; m++)
            if (strcmp(c->methods[m].label, c->methods[k].label) == 0)
                return tcb_fail(err, TCB_ERR_INPUT,
                                "%s.name: duplicate method label '%s' (also methods[%d])", w,
                                c->methods[k].label, m);
    }
    return TCB_OK;
}

static int parse_seeds(const cJSON *root, const char *origin, tcb_config *c, tcb_error *err)
{
    char top[WHERE_MAX], w[WHERE_MAX];
    snprintf(top, sizeof top, "%s:", origin);
    const cJSON *arr;
    int rc = fix_top(get_array(root, "seeds", top, 0, &arr, err), origin, err);
    if (rc) return rc;
    if (!arr) { /* default: the single seed 0 */
        c->seeds = calloc(1, sizeof *c->seeds);
        if (!c->seeds) return tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", origin);
        c->n_seeds = 1;
        return TCB_OK;
    }
    snprintf(w, sizeof w, "%s: seeds", origin);
    return parse_seed_list(arr, w, &c->seeds, &c->n_seeds, err);
}

static int parse_plugins(const cJSON *root, const char *origin, tcb_config *c, tcb_error *err)
{
    char top[WHERE_MAX];
    snprintf(top, sizeof top, "%s:", origin);
    const cJSON *arr;
    int rc = fix_top(get_array(root, "plugins", top, 0, &arr, err), origin, err);
    if (rc || !arr) return rc;
    int n = cJSON_GetArraySize(arr);
    c->plugins = calloc((size_t)n + 1, sizeof *c->plugins);
    if (!c->plugins) return tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", origin);
    for (int k = 0; k < n; k++) {
        const cJSON *p = cJSON_GetArrayItem(arr, k);
        if (!cJSON_IsString(p) || !p->valuestring[0])
            return tcb_fail(err, TCB_ERR_INPUT, "%s: plugins[%d]: expected a non-empty path",
                            origin, k);
        c->plugins[k] = strdup(p->valuestring);
        if (!c->plugins[k]) return tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", origin);
        c->n_plugins = k + 1;
    }
    return TCB_OK;
}

/* One protocol name's bit, 0 when unknown. */
static int protocol_bit(const cJSON *v)
{
    for (int k = 0; cJSON_IsString(v) && tcb_config_protocol_names[k]; k++)
        if (!strcmp(v->valuestring, tcb_config_protocol_names[k])) return 1 << k;
    return 0;
}

/* "protocol": a name, or a non-empty list of distinct names; default pairs. */
static int parse_protocol(const cJSON *ev, const char *where, tcb_config *c, tcb_error *err)
{
    const cJSON *p = cJSON_GetObjectItemCaseSensitive(ev, "protocol");
    c->protocols = p ? protocol_bit(p) : TCB_PROTOCOL_PAIRS;
    for (const cJSON *e = cJSON_IsArray(p) ? p->child : NULL; e; e = e->next) {
        int bit = protocol_bit(e);
        c->protocols = bit && !(c->protocols & bit) && c->protocols != -1 ? c->protocols | bit : -1;
    }
    if (c->protocols > 0) return TCB_OK;
    char *text = cJSON_PrintUnformatted(p);
    int rc = tcb_fail(err, TCB_ERR_INPUT,
                      "%s.protocol: expected \"pairs\", \"clips\" or a list of them (each once), got %.200s",
                      where, text ? text : "?");
    cJSON_free(text);
    return rc;
}

static int parse_evaluation(const cJSON *root, const char *origin, tcb_config *c, tcb_error *err)
{
    char w[WHERE_MAX];
    snprintf(w, sizeof w, "%s: evaluation", origin);
    const cJSON *ev = cJSON_GetObjectItemCaseSensitive(root, "evaluation");
    cJSON *empty = NULL;
    if (!ev) ev = empty = cJSON_CreateObject();
    long long pairs, split_seed, pool, pool_seed, input, clips, surface;
    int rc = tcb_json_expect_keys(ev, w, eval_keys, err);
    if (!rc) rc = parse_protocol(ev, w, c, err);
    if (!rc && cJSON_HasObjectItem(ev, "clips") && !(c->protocols & TCB_PROTOCOL_CLIPS))
        rc = tcb_fail(err, TCB_ERR_INPUT, "%s.clips: only with the clip protocol (\"protocol\": \"clips\")", w);
    if (!rc) rc = tcb_json_int(ev, "clips", w, 0, TCB_DEFAULT_EVAL_CLIPS, 1, 100000, &clips, err);
    if (!rc)
        rc = tcb_json_int(ev, "pairs", w, 0, TCB_DEFAULT_EVAL_PAIRS, 1, 1000000, &pairs, err);
    if (!rc) rc = tcb_json_int(ev, "split_seed", w, 0, 2021, 0, LLONG_MAX, &split_seed, err);
    if (!rc)
        rc = tcb_json_int(ev, "pool_size", w, 0, TCB_DEFAULT_POOL_SIZE, 1, 10000000, &pool, err);
    if (!rc) rc = tcb_json_int(ev, "pool_seed", w, 0, 0, 0, LLONG_MAX, &pool_seed, err);
    if (!rc)
        rc = tcb_json_int(ev, "input_points", w, 0, TCB_DEFAULT_INPUT_POINTS, 1, 10000000,
                          &input, err);
    if (!rc)
        rc = tcb_json_int(ev, "surface_samples", w, 0, TCB_DEFAULT_SURFACE_SAMPLES, 1, 10000000, &surface, err);
    int normals = 0, recon_frame = 0;
    if (!rc) rc = tcb_json_enum(ev, "fit", w, 0, 0, tcb_config_fit_names, &c->fit_per_clip, err);
    if (!rc) rc = tcb_json_enum(ev, "input_normals", w, 0, 0, tcb_config_input_normals_names, &normals, err);
    if (!rc) rc = tcb_json_enum(ev, "recon_frame", w, 0, 0, tcb_recon_frame_names, &recon_frame, err);
    /* A clip fitted alone has no frames outside it for pairs to reach. */
    if (!rc && c->fit_per_clip && c->protocols != TCB_PROTOCOL_CLIPS)
        rc = tcb_fail(err, TCB_ERR_INPUT, "%s.fit: per_clip needs \"protocol\": \"clips\" alone", w);
    cJSON_Delete(empty);
    if (rc) return rc;
    c->eval_pairs = (int)pairs;
    c->split_seed = (uint64_t)split_seed;
    c->eval_clips = (int)clips;
    c->pool_size = (int)pool;
    c->pool_seed = (uint64_t)pool_seed;
    c->input_points = (int)input;
    c->surface_samples = (int)surface;
    c->input_normals = (tcb_input_normals)normals;
    c->recon_frame = (tcb_recon_frame)recon_frame;
    return TCB_OK;
}

/* name, output, splits_dir, cache_dir, threads. */
static int parse_scalars(const cJSON *root, const char *origin, tcb_config *c, tcb_error *err)
{
    char top[WHERE_MAX];
    snprintf(top, sizeof top, "%s:", origin);
    const char *name, *output, *splits, *cache;
    long long threads;
    int rc = tcb_json_str(root, "name", top, 1, NULL, &name, err);
    if (!rc) rc = check_name(name, sizeof c->name, top, "name", err);
    if (!rc) rc = tcb_json_str(root, "output", top, 0, NULL, &output, err);
    if (!rc) rc = tcb_json_str(root, "splits_dir", top, 0, "splits", &splits, err);
    if (!rc) rc = tcb_json_str(root, "cache_dir", top, 0, ".tcbench-cache", &cache, err);
    if (!rc) rc = tcb_json_int(root, "threads", top, 0, 2, 1, 1024, &threads, err);
    if (!rc && output) rc = copy_str(c->output, sizeof c->output, output, top, "output", err);
    if (!rc) rc = copy_str(c->splits_dir, sizeof c->splits_dir, splits, top, "splits_dir", err);
    if (!rc) rc = copy_str(c->cache_dir, sizeof c->cache_dir, cache, top, "cache_dir", err);
    if (rc) return fix_top(rc, origin, err);
    snprintf(c->name, sizeof c->name, "%s", name);
    if (!output) snprintf(c->output, sizeof c->output, "runs/%s", name);
    if (!c->output[0] || !c->splits_dir[0])
        return tcb_fail(err, TCB_ERR_INPUT, "%s: %s: must not be empty", origin,
                        c->output[0] ? "splits_dir" : "output");
    c->threads = (int)threads;
    return TCB_OK;
}

/* "reference": { "source": "iccv21", "tables": ["5", "7"] } */
static int parse_reference(const cJSON *root, const char *origin, tcb_config *c, tcb_error *err)
{
    char w[WHERE_MAX];
    snprintf(w, sizeof w, "%s: reference", origin);
    const cJSON *ref = cJSON_GetObjectItemCaseSensitive(root, "reference");
    if (!ref) return TCB_OK;
    const char *source;
    const cJSON *tables;
    int rc = tcb_json_expect_keys(ref, w, reference_keys, err);
    if (!rc) rc = tcb_json_str(ref, "source", w, 1, NULL, &source, err);
    if (!rc) rc = check_name(source, sizeof c->reference, w, "source", err);
    if (!rc) rc = get_array(ref, "tables", w, 1, &tables, err);
    if (rc) return rc;
    int n = cJSON_GetArraySize(tables);
    if (n < 1 || n > TCB_REFERENCE_TABLES_MAX)
        return tcb_fail(err, TCB_ERR_INPUT, "%s.tables: must list 1 to %d tables", w, TCB_REFERENCE_TABLES_MAX);
    for (int k = 0; k < n; k++) {
        const cJSON *t = cJSON_GetArrayItem(tables, k);
        if (!cJSON_IsString(t) || !t->valuestring[0] || strlen(t->valuestring) >= sizeof c->reference_tables[k])
            return tcb_fail(err, TCB_ERR_INPUT, "%s.tables[%d]: expected a table id of 1 to %zu characters", w, k,
                            sizeof c->reference_tables[k] - 1);
        snprintf(c->reference_tables[k], sizeof c->reference_tables[k], "%s", t->valuestring);
    }
    snprintf(c->reference, sizeof c->reference, "%s", source);
    c->n_reference_tables = n;
    return TCB_OK;
}

int tcb_config_parse(const char *text, const char *origin, tcb_config *out, tcb_error *err)
{
    return tcb_config_parse_opts(text, origin, NULL, out, err);
}

int tcb_config_parse_opts(const char *text, const char *origin, const tcb_config_opts *opts,
                          tcb_config *out, tcb_error *err)
{
    memset(out, 0, sizeof *out);
    if (strlen(origin) >= sizeof out->path)
        return tcb_fail(err, TCB_ERR_INPUT, "%s: path too long", origin);
    snprintf(out->path, sizeof out->path, "%s", origin);
    cJSON *root;
    int rc = tcb_json_parse(text, origin, &root, err);
    if (rc) return rc;
    char top[WHERE_MAX];
    snprintf(top, sizeof top, "%s:", origin);
    rc = tcb_json_expect_object(root, origin, err);
    if (!rc) rc = tcb_config_apply_opts(root, origin, opts, err);
    if (!rc) rc = tcb_config_resolve_paths(root, origin, err);
    if (!rc) rc = fix_top(tcb_json_expect_keys(root, top, top_keys, err), origin, err);
    if (!rc) rc = parse_scalars(root, origin, out, err);
    if (!rc) rc = parse_plugins(root, origin, out, err);
    if (!rc) rc = parse_seeds(root, origin, out, err);
    if (!rc) rc = parse_evaluation(root, origin, out, err);
    if (!rc) rc = parse_datasets(root, origin, out, err);
    if (!rc) rc = parse_methods(root, origin, out, err);
    if (!rc) rc = parse_reference(root, origin, out, err);
    cJSON_Delete(root);
    if (!rc) {
        out->json_text = tcb_config_normalized_json(out);
        if (!out->json_text) rc = tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", origin);
    }
    if (rc) tcb_config_free(out);
    return rc;
}

int tcb_config_load(const char *path, tcb_config *out, tcb_error *err)
{
    return tcb_config_load_opts(path, NULL, out, err);
}

int tcb_config_load_opts(const char *path, const tcb_config_opts *opts, tcb_config *out,
                         tcb_error *err)
{
    memset(out, 0, sizeof *out);
    char *text;
    int rc = tcb_read_file(path, &text, NULL, err);
    if (rc) return rc;
    rc = tcb_config_parse_opts(text, path, opts, out, err);
    free(text);
    return rc;
}

void tcb_config_free(tcb_config *c)
{
    if (!c) return;
    for (int k = 0; k < c->n_plugins; k++) free(c->plugins[k]);
    free(c->plugins);
    free(c->seeds);
    for (int k = 0; k < c->n_datasets; k++) {
        for (int s = 0; s < c->datasets[k].n_subjects; s++) free(c->datasets[k].subjects[s]);
        free(c->datasets[k].subjects);
        free(c->datasets[k].sequences);
    }
    free(c->datasets);
    for (int k = 0; k < c->n_methods; k++) {
        free(c->methods[k].params_json);
        free(c->methods[k].seeds);
        free(c->methods[k].only_on);
    }
    free(c->methods);
    free(c->json_text);
    memset(c, 0, sizeof *c);
}
