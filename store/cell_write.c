/* The results store: cell paths and the writer of "tcbench-cell/1" files. */
#include "tcb/results.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "store/cell_format.h"
#include "tcb/fsutil.h"
#include "tcb/json.h"
#include "tcb/version.h"

const char *const tcb_cell_status_names[] = {"ok", "failed", "diverged", NULL};
const char *const tcb_cell_role_names[] = {"train", "validation", "test", NULL};
const char *const tcb_cell_pair_columns[] = {
    "i",   "j",   "n",   "sl2",    "sl2_m2",  "sl2sq",   "sl2sq_m2",        "rank",
    "rank_m2", "auc", "cd", "geo", "geo_m2", "geo_auc", "geo_unreachable", NULL};

const char *tcb_cell_status_name(tcb_cell_status s)
{
    return s >= TCB_CELL_OK && s <= TCB_CELL_DIVERGED ? tcb_cell_status_names[s] : "unknown";
}

/* A path component must not escape its directory. */
static int check_component(const char *what, const char *name, tcb_error *err)
{
    if (!name[0] || strchr(name, '/') || !strcmp(name, ".") || !strcmp(name, ".."))
        return tcb_fail(err, TCB_ERR_INPUT, "invalid %s name \"%s\" for a results path", what,
                        name);
    return TCB_OK;
}

int tcb_cell_path(char *out, size_t size, const char *run_dir, const char *dataset,
                  const char *sequence, const char *method, int seed, tcb_error *err)
{
    int rc;
    if ((rc = check_component("dataset", dataset, err)) ||
        (rc = check_component("sequence", sequence, err)) ||
        (rc = check_component("method", method, err)))
        return rc;
    return tcb_path_join(out, size, err, "%s/cells/%s/%s/%s/seed_%d.json", run_dir, dataset,
                         sequence, method, seed);
}

/* cJSON builders report allocation failure by returning NULL; `ok` collects
 * it so the writer stays a flat list of fields. */
typedef struct builder {
    int ok;
} builder;

static cJSON *add(builder *b, cJSON *obj, const char *key, cJSON *item)
{
    if (!item) {
        b->ok = 0;
        return NULL;
    }
    if (!cJSON_AddItemToObject(obj, key, item)) {
        cJSON_Delete(item);
        b->ok = 0;
        return NULL;
    }
    return item;
}

/* cJSON prints 15 significant digits whenever they come within an ulp or
 * so; a results file must give back the very bits, so print the shortest
 * of %.15g … %.17g that does. */
static cJSON *num_or_null(double x)
{
    if (!isfinite(x)) return cJSON_CreateNull();
    char buf[32];
    for (int digits = 15; digits <= 17; digits++) {
        snprintf(buf, sizeof buf, "%.*g", digits, x);
        if (strtod(buf, NULL) == x) break;
    }
    return cJSON_CreateRaw(buf);
}

static void add_num(builder *b, cJSON *obj, const char *key, double x)
{
    add(b, obj, key, num_or_null(x));
}

static void add_str(builder *b, cJSON *obj, const char *key, const char *s)
{
    add(b, obj, key, cJSON_CreateString(s));
}

static int append(builder *b, cJSON *arr, cJSON *item)
{
    if (!item || !cJSON_AddItemToArray(arr, item)) {
        cJSON_Delete(item);
        return b->ok = 0;
    }
    return 1;
}

static void add_stat(builder *b, cJSON *obj, const char *key, const tcb_stat *s)
{
    cJSON *o = add(b, obj, key, cJSON_CreateObject());
    if (!o) return;
    add_num(b, o, "n", s->n);
    add_num(b, o, "mean", s->mean);
    add_num(b, o, "m2", s->m2);
}

static void add_summary(builder *b, cJSON *root, const tcb_summary *s)
{
    cJSON *o = add(b, root, "summary", cJSON_CreateObject());
    if (!o) return;
    add_num(b, o, "n_pairs", s->n_pairs);
    add_stat(b, o, "sl2", &s->sl2);
    add_stat(b, o, "sl2sq", &s->sl2sq);
    add_stat(b, o, "rank", &s->rank);
    add_stat(b, o, "auc", &s->auc);
    if (s->cd.n > 0)
        add_stat(b, o, "cd", &s->cd);
    else
        add(b, o, "cd", cJSON_CreateNull());
    cJSON *pck = add(b, o, "pck", cJSON_CreateArray());
    for (int k = 0; pck && k < TCB_PCK_STEPS; k++) append(b, pck, num_or_null(s->pck[k]));
    add_stat(b, o, "geo", &s->geo);
    add_stat(b, o, "geo_auc", &s->geo_auc);
    cJSON *geo_pck = add(b, o, "geo_pck", cJSON_CreateArray());
    for (int k = 0; geo_pck && k < TCB_GEO_PCK_STEPS; k++)
        append(b, geo_pck, num_or_null(s->geo_pck[k]));
    add_num(b, o, "geo_unreachable", s->geo_unreachable);
    if (s->corr.n > 0) add_stat(b, o, "corr", &s->corr);
    if (s->corr_mesh.n > 0) add_stat(b, o, "corr_mesh", &s->corr_mesh);
    for (int m = 0; m < TCB_N_RECON; m++)
        if (s->recon[m].n > 0) add_stat(b, o, tcb_recon_names[m], &s->recon[m]);
}

/* The reconstruction metrics per evaluated frame, when the cell has them. */
static void add_surface(builder *b, cJSON *root, const tcb_cell_result *c)
{
    if (c->n_surface == 0) return;
    cJSON *o = add(b, root, "surface", cJSON_CreateObject());
    if (!o) return;
    add_num(b, o, "samples", c->surface_samples);
    if (c->surface_frame != TCB_RECON_FRAME_SEQUENCE)
        add_str(b, o, "frame", tcb_recon_frame_names[c->surface_frame]);
    cJSON *cols = add(b, o, "columns", cJSON_CreateArray());
    append(b, cols, cJSON_CreateString("frame"));
    for (int m = 0; cols && m < TCB_N_RECON; m++) append(b, cols, cJSON_CreateString(tcb_recon_names[m]));
    cJSON *rows = add(b, o, "rows", cJSON_CreateArray());
    for (int k = 0; rows && k < c->n_surface && b->ok; k++) {
        cJSON *row = cJSON_CreateArray();
        if (!append(b, rows, row)) return;
        append(b, row, num_or_null(c->surface[k].frame));
        for (int m = 0; m < TCB_N_RECON; m++) append(b, row, num_or_null(c->surface[k].v[m]));
    }
}

/* The clip protocol's split and rows, when the cell scored clips. */
static void add_clips(builder *b, cJSON *root, const tcb_cell_result *c)
{
    if (c->n_clips == 0) return;
    static const char *const columns[] = {"start", "corr", "err", "corr_mesh"};
    /* corr_mesh only when a clip has it, so that the cells of methods
     * without surfaces read as they did before it. */
    int mesh = c->summary.corr_mesh.n > 0;
    cJSON *o = add(b, root, "clips", cJSON_CreateObject());
    if (!o) return;
    add_str(b, o, "path", c->clips_path);
    add_num(b, o, "seed", (double)c->clips_seed);
    add_num(b, o, "clip_frames", TCB_CLIP_FRAMES);
    add_num(b, o, "n_clips", c->n_clips);
    add(b, o, "columns", cJSON_CreateStringArray(columns, 3 + mesh));
    cJSON *rows = add(b, o, "rows", cJSON_CreateArray());
    for (int k = 0; rows && k < c->n_clips && b->ok; k++) {
        const tcb_clip_record *r = &c->clips[k];
        cJSON *row = cJSON_CreateArray();
        if (!append(b, rows, row) || !append(b, row, num_or_null(r->start)) ||
            !append(b, row, num_or_null(r->corr)))
            return;
        cJSON *err = cJSON_CreateArray();
        if (!append(b, row, err)) return;
        for (int t = 0; t < TCB_CLIP_FRAMES - 1; t++) append(b, err, num_or_null(r->err[t]));
        if (mesh) append(b, row, num_or_null(r->corr_mesh));
    }
}

void tcb_pair_record_row(const tcb_pair_record *r, double *v)
{
    /* A pair without geodesic values (a cell loaded from an older file)
     * writes them as null. */
    int geo = r->geo.n > 0;
    const double row[TCB_N_PAIR_COLUMNS] = {r->i,         r->j,          r->sl2.n,
                                            r->sl2.mean,  r->sl2.m2,     r->sl2sq.mean,
                                            r->sl2sq.m2,  r->rank.mean,  r->rank.m2,
                                            r->auc,       r->cd,
                                            geo ? r->geo.mean : NAN,
                                            geo ? r->geo.m2 : NAN,
                                            geo ? r->geo_auc : NAN,
                                            geo ? r->geo_unreachable : NAN};
    memcpy(v, row, sizeof row);
}

/* pairs: [n_pairs][TCB_N_PAIR_COLUMNS] in tcb_cell_pair_columns order. */
static void add_pairs(builder *b, cJSON *root, const tcb_cell_result *c)
{
    cJSON *cols = add(b, root, "pair_columns", cJSON_CreateStringArray(tcb_cell_pair_columns,
                                                                       TCB_N_PAIR_COLUMNS));
    cJSON *rows = add(b, root, "pairs", cJSON_CreateArray());
    if (!cols || !rows) return;
    for (int p = 0; p < c->n_pairs && b->ok; p++) {
        double v[TCB_N_PAIR_COLUMNS];
        tcb_pair_record_row(&c->pairs[p], v);
        cJSON *row = cJSON_CreateArray();
        if (!append(b, rows, row)) return;
        for (int k = 0; k < TCB_N_PAIR_COLUMNS; k++) append(b, row, num_or_null(v[k]));
    }
}

static int check_for_save(const char *path, const tcb_cell_result *c, tcb_error *err)
{
    if (c->status < TCB_CELL_OK || c->status > TCB_CELL_DIVERGED)
        return tcb_fail(err, TCB_ERR_INTERNAL, "%s: invalid cell status %d", path, (int)c->status);
    if (c->n_pairs < 0 || (c->n_pairs > 0 && !c->pairs))
        return tcb_fail(err, TCB_ERR_INTERNAL, "%s: %d pairs without records", path, c->n_pairs);
    if (c->n_clips < 0 || (c->n_clips > 0 && !c->clips) || (double)c->clips_seed > TCB_JSON_INT_MAX)
        return tcb_fail(err, TCB_ERR_INTERNAL, "%s: %d clips without records, or a clip seed past 2^53", path,
                        c->n_clips);
    if (c->n_surface < 0 || (c->n_surface > 0 && (!c->surface || c->surface_samples < 1)))
        return tcb_fail(err, TCB_ERR_INTERNAL, "%s: %d surface frames without records or samples", path,
                        c->n_surface);
    if ((double)c->split_seed > TCB_JSON_INT_MAX)
        return tcb_fail(err, TCB_ERR_INPUT, "%s: split seed %llu exceeds 2^53", path,
                        c->split_seed);
    int role_known = 0;
    for (int k = 0; tcb_cell_role_names[k]; k++)
        role_known |= !strcmp(c->role, tcb_cell_role_names[k]);
    if (!role_known)
        return tcb_fail(err, TCB_ERR_INTERNAL, "%s: invalid role \"%s\"", path, c->role);
    /* One "n" column serves the per-vertex statistics of a pair (the
     * geodesic one has it too, or none). */
    for (int p = 0; p < c->n_pairs; p++) {
        const tcb_pair_record *r = &c->pairs[p];
        if (r->sl2sq.n != r->sl2.n || r->rank.n != r->sl2.n || (r->geo.n && r->geo.n != r->sl2.n))
            return tcb_fail(err, TCB_ERR_INTERNAL, "%s: pair %d: statistics disagree on n",
                            path, p);
    }
    return TCB_OK;
}

cJSON *tcb_cell_to_json(const char *path, const tcb_cell_result *c, tcb_error *err)
{
    cJSON *params = cJSON_Parse(c->params_json ? c->params_json : "{}");
    if (!cJSON_IsObject(params)) {
        cJSON_Delete(params);
        tcb_fail(err, TCB_ERR_INPUT, "%s: params: not a JSON object: %.200s", path,
                 c->params_json);
        return NULL;
    }
    builder b = {1};
    cJSON *root = cJSON_CreateObject();
    if (!root) {
        cJSON_Delete(params);
        tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", path);
        return NULL;
    }
    add_str(&b, root, "format", TCB_CELL_FORMAT);
    add_str(&b, root, "dataset", c->dataset);
    add_str(&b, root, "sequence", c->sequence);
    add_str(&b, root, "role", c->role);
    add_str(&b, root, "method", c->method);
    add_str(&b, root, "method_impl", c->method_impl);
    add(&b, root, "params", params);
    add_num(&b, root, "seed", c->seed);
    add_str(&b, root, "status", tcb_cell_status_name(c->status));
    add_str(&b, root, "message", c->message);
    add_str(&b, root, "git_revision", c->git_revision);
    /* A loaded cell keeps the version that wrote it when written again. */
    add_str(&b, root, "tcbench_version", c->tcbench_version[0] ? c->tcbench_version : TCB_VERSION);
    cJSON *t = add(&b, root, "timings", cJSON_CreateObject());
    if (t) {
        add_num(&b, t, "load_s", c->load_s);
        add_num(&b, t, "fit_s", c->fit_s);
        add_num(&b, t, "eval_s", c->eval_s);
    }
    add_num(&b, root, "peak_rss_kb", (double)c->peak_rss_kb);
    cJSON *sp = add(&b, root, "split", cJSON_CreateObject());
    if (sp) {
        add_str(&b, sp, "path", c->split_path);
        add_num(&b, sp, "seed", (double)c->split_seed);
        add_num(&b, sp, "n_pairs", c->n_pairs);
    }
    if (c->plugin_path[0]) {
        cJSON *pl = add(&b, root, "plugin", cJSON_CreateObject());
        if (pl) {
            add_str(&b, pl, "path", c->plugin_path);
            add_str(&b, pl, "fnv1a64", c->plugin_digest);
            add_num(&b, pl, "abi", c->plugin_abi);
            add_str(&b, pl, "version", c->plugin_version);
        }
    }
    if (c->normals[0]) add_str(&b, root, "normals", c->normals);
    if (c->no_faces) add(&b, root, "faces", cJSON_CreateBool(0));
    add_summary(&b, root, &c->summary);
    add_pairs(&b, root, c);
    add_clips(&b, root, c);
    add_surface(&b, root, c);
    if (!b.ok) {
        cJSON_Delete(root);
        tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", path);
        return NULL;
    }
    return root;
}

int tcb_cell_save(const char *path, const tcb_cell_result *c, tcb_error *err)
{
    int rc = check_for_save(path, c, err);
    if (rc) return rc;
    cJSON *root = tcb_cell_to_json(path, c, err);
    if (!root) return err ? (int)err->code : TCB_ERR_INPUT;
    rc = tcb_json_save(path, root, err);
    cJSON_Delete(root);
    return rc;
}

void tcb_cell_drop_rows(tcb_cell_result *c)
{
    free(c->pairs);
    free(c->clips);
    free(c->surface);
    c->pairs = NULL;
    c->clips = NULL;
    c->surface = NULL;
    c->n_pairs = 0;
    c->n_clips = 0;
    c->n_surface = 0;
}

void tcb_cell_free(tcb_cell_result *c)
{
    if (!c) return;
    free(c->params_json);
    c->params_json = NULL;
    tcb_cell_drop_rows(c);
}
