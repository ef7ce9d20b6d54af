/* The reader of "tcbench-cell/1" files: every field validated, errors
 * naming the file and the key. */
#include "tcb/results.h"

#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "store/cell_format.h"
#include "tcb/json.h"

static const char *const TOP_KEYS[] = {
    "format",       "dataset",         "sequence", "role",        "method",
    "method_impl",  "params",          "seed",     "status",      "message",
    "git_revision", "tcbench_version", "timings",  "peak_rss_kb", "split",
    "summary",      "pair_columns",    "pairs",    "clips",       "surface", "plugin", "normals", "faces", NULL};
static const char *const TIMING_KEYS[] = {"load_s", "fit_s", "eval_s", NULL};
static const char *const SPLIT_KEYS[] = {"path", "seed", "n_pairs", NULL};
static const char *const PLUGIN_KEYS[] = {"path", "fnv1a64", "abi", "version", NULL};
static const char *const SUMMARY_KEYS[] = {"n_pairs", "sl2",     "sl2sq",   "rank",
                                           "auc",     "cd",      "pck",     "geo",
                                           "geo_auc", "geo_pck", "geo_unreachable", "corr",   "corr_mesh",
                                           "cdl2",    "nc",      "fscore05", "fscore1", NULL};
/* The summary's geodesic keys: all or none (none in a cell written before
 * the geodesic error). */
static const char *const GEO_KEYS[] = {"geo", "geo_auc", "geo_pck", "geo_unreachable", NULL};
static const char *const STAT_KEYS[] = {"n", "mean", "m2", NULL};
/* The clip protocol's (absent in a cell without clips). */
static const char *const CLIPS_KEYS[] = {"path", "seed", "clip_frames", "n_clips", "columns", "rows", NULL};
/* The reconstruction metrics' (absent in a cell without them). */
static const char *const SURFACE_KEYS[] = {"samples", "frame", "columns", "rows", NULL};
static const char *const NORMALS_NAMES[] = {"gt", "estimated", NULL};

/* Key paths for messages ("file: summary.sl2.mean"); a path too long for
 * the buffer is cut, which only shortens a message. */
__attribute__((format(printf, 3, 4))) static void key_path(char *out, size_t size,
                                                           const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(out, size, fmt, ap);
    va_end(ap);
}

/* A float metric: a number, or null for a non-finite value. */
static int value_or_null(const cJSON *item, const char *where, double *out, tcb_error *err)
{
    if (cJSON_IsNull(item)) {
        *out = NAN;
        return TCB_OK;
    }
    if (!cJSON_IsNumber(item))
        return tcb_fail(err, TCB_ERR_INPUT, "%s: expected a number or null", where);
    *out = item->valuedouble;
    return TCB_OK;
}

static int num_or_null_key(const cJSON *obj, const char *key, const char *where, double *out,
                           tcb_error *err)
{
    char at[TCB_ERRMSG_MAX];
    key_path(at, sizeof at, "%s.%s", where, key);
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!item) return tcb_fail(err, TCB_ERR_INPUT, "%s: missing key", at);
    return value_or_null(item, at, out, err);
}

/* A required sub-object with exactly the allowed keys; *where gets its path. */
static int object_key(const cJSON *obj, const char *key, const char *where,
                      const char *const *allowed, const cJSON **out, char *sub, size_t sub_size,
                      tcb_error *err)
{
    key_path(sub, sub_size, "%s.%s", where, key);
    *out = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!*out) return tcb_fail(err, TCB_ERR_INPUT, "%s: missing key", sub);
    int rc = tcb_json_expect_object(*out, sub, err);
    return rc ? rc : tcb_json_expect_keys(*out, sub, allowed, err);
}

static int copy_str(const cJSON *obj, const char *key, const char *where, char *dst,
                    size_t size, tcb_error *err)
{
    const char *s;
    int rc = tcb_json_str(obj, key, where, 1, NULL, &s, err);
    if (rc) return rc;
    if (strlen(s) >= size)
        return tcb_fail(err, TCB_ERR_INPUT, "%s.%s: longer than %zu characters", where, key,
                        size - 1);
    memcpy(dst, s, strlen(s) + 1);
    return TCB_OK;
}

static int load_stat(const cJSON *obj, const char *key, const char *where, tcb_stat *s,
                     tcb_error *err)
{
    char sub[TCB_ERRMSG_MAX];
    const cJSON *o;
    int rc = object_key(obj, key, where, STAT_KEYS, &o, sub, sizeof sub, err);
    if (rc) return rc;
    if ((rc = tcb_json_num(o, "n", sub, 1, 0, 0, INFINITY, &s->n, err))) return rc;
    if ((rc = num_or_null_key(o, "mean", sub, &s->mean, err))) return rc;
    return num_or_null_key(o, "m2", sub, &s->m2, err);
}

/* A PCK curve: an array of `steps` numbers (null for non-finite). */
static int load_curve(const cJSON *o, const char *key, const char *where, int steps, double *out,
                      tcb_error *err)
{
    const cJSON *curve = cJSON_GetObjectItemCaseSensitive(o, key);
    if (!cJSON_IsArray(curve) || cJSON_GetArraySize(curve) != steps)
        return tcb_fail(err, TCB_ERR_INPUT, "%s.%s: expected an array of %d numbers", where, key,
                        steps);
    int k = 0;
    for (const cJSON *v = curve->child; v; v = v->next, k++) {
        char at[TCB_ERRMSG_MAX];
        key_path(at, sizeof at, "%s.%s[%d]", where, key, k);
        int rc = value_or_null(v, at, &out[k], err);
        if (rc) return rc;
    }
    return TCB_OK;
}

/* The geodesic keys when the cell has them; without, the summary keeps
 * geo.n = geo_auc.n = 0 (no geodesic values). */
static int load_summary_geodesic(const cJSON *o, const char *sub, tcb_summary *s, tcb_error *err)
{
    int present = 0, rc;
    for (int k = 0; GEO_KEYS[k]; k++) present += cJSON_HasObjectItem(o, GEO_KEYS[k]);
    if (!present) return TCB_OK;
    for (int k = 0; GEO_KEYS[k]; k++)
        if (!cJSON_HasObjectItem(o, GEO_KEYS[k]))
            return tcb_fail(err, TCB_ERR_INPUT, "%s.%s: missing key (the geodesic keys go together)",
                            sub, GEO_KEYS[k]);
    if ((rc = load_stat(o, "geo", sub, &s->geo, err)) ||
        (rc = load_stat(o, "geo_auc", sub, &s->geo_auc, err)) ||
        (rc = load_curve(o, "geo_pck", sub, TCB_GEO_PCK_STEPS, s->geo_pck, err)))
        return rc;
    return tcb_json_num(o, "geo_unreachable", sub, 1, 0, 0, TCB_JSON_INT_MAX, &s->geo_unreachable,
                        err);
}

static int load_summary(const cJSON *root, const char *where, tcb_summary *s, tcb_error *err)
{
    char sub[TCB_ERRMSG_MAX];
    const cJSON *o;
    long long n;
    int rc = object_key(root, "summary", where, SUMMARY_KEYS, &o, sub, sizeof sub, err);
    if (rc || (rc = tcb_json_int(o, "n_pairs", sub, 1, 0, 0, INT_MAX, &n, err))) return rc;
    s->n_pairs = (int)n;
    if ((rc = load_stat(o, "sl2", sub, &s->sl2, err)) ||
        (rc = load_stat(o, "sl2sq", sub, &s->sl2sq, err)) ||
        (rc = load_stat(o, "rank", sub, &s->rank, err)) ||
        (rc = load_stat(o, "auc", sub, &s->auc, err)))
        return rc;
    const cJSON *cd = cJSON_GetObjectItemCaseSensitive(o, "cd");
    if (cJSON_IsNull(cd))
        s->cd = (tcb_stat){0, 0, 0};
    else if ((rc = load_stat(o, "cd", sub, &s->cd, err)))
        return rc;
    if ((rc = load_curve(o, "pck", sub, TCB_PCK_STEPS, s->pck, err))) return rc;
    if (cJSON_HasObjectItem(o, "corr") && (rc = load_stat(o, "corr", sub, &s->corr, err))) return rc;
    if (cJSON_HasObjectItem(o, "corr_mesh") && (rc = load_stat(o, "corr_mesh", sub, &s->corr_mesh, err))) return rc;
    for (int m = 0; m < TCB_N_RECON; m++)
        if (cJSON_HasObjectItem(o, tcb_recon_names[m]) &&
            (rc = load_stat(o, tcb_recon_names[m], sub, &s->recon[m], err)))
            return rc;
    return load_summary_geodesic(o, sub, s, err);
}

/* The columns, all of them or the Euclidean ones of an older cell; their
 * count goes to *n. */
static int load_pair_columns(const cJSON *root, const char *where, int *n, tcb_error *err)
{
    const cJSON *cols = cJSON_GetObjectItemCaseSensitive(root, "pair_columns");
    *n = cJSON_IsArray(cols) ? cJSON_GetArraySize(cols) : -1;
    int ok = *n == TCB_N_PAIR_COLUMNS || *n == TCB_N_PAIR_COLUMNS_EUCLIDEAN;
    int k = 0;
    for (const cJSON *c = ok ? cols->child : NULL; c; c = c->next, k++)
        ok = ok && cJSON_IsString(c) && !strcmp(c->valuestring, tcb_cell_pair_columns[k]);
    if (!ok)
        return tcb_fail(err, TCB_ERR_INPUT,
                        "%s.pair_columns: expected [\"i\", \"j\", \"n\", \"sl2\", …, \"cd\", "
                        "\"geo\", …, \"geo_unreachable\"] (%d columns of format %s, or the first "
                        "%d of a cell without geodesic error)",
                        where, TCB_N_PAIR_COLUMNS, TCB_CELL_FORMAT, TCB_N_PAIR_COLUMNS_EUCLIDEAN);
    return TCB_OK;
}

static int pair_index(const cJSON *v, const char *at, int *out, tcb_error *err)
{
    if (!cJSON_IsNumber(v) || v->valuedouble < 0 || v->valuedouble > INT_MAX ||
        v->valuedouble != floor(v->valuedouble))
        return tcb_fail(err, TCB_ERR_INPUT, "%s: expected a frame index", at);
    *out = (int)v->valuedouble;
    return TCB_OK;
}

/* The geodesic columns x[9 ..] (geo, geo_m2, geo_auc, geo_unreachable)
 * of a pair with n vertices: all null (none), or all numbers. */
static int pair_geodesic(const double *x, double n, const char *at, tcb_pair_record *r,
                         tcb_error *err)
{
    int nulls = isnan(x[9]) + isnan(x[10]) + isnan(x[11]) + isnan(x[12]);
    if (nulls == 4) return TCB_OK;
    if (nulls || !(x[12] >= 0) || x[12] > n || x[12] != floor(x[12]))
        return tcb_fail(err, TCB_ERR_INPUT,
                        "%s: the geodesic columns must be numbers (geo_unreachable a count of "
                        "at most n) or all null",
                        at);
    r->geo = (tcb_stat){n, x[9], x[10]};
    r->geo_auc = x[11];
    r->geo_unreachable = (int)x[12];
    return TCB_OK;
}

/* A row of n_cols values (TCB_N_PAIR_COLUMNS, or the Euclidean ones). */
static int load_pair(const cJSON *row, int n_cols, const char *at, tcb_pair_record *r,
                     tcb_error *err)
{
    if (!cJSON_IsArray(row) || cJSON_GetArraySize(row) != n_cols)
        return tcb_fail(err, TCB_ERR_INPUT, "%s: expected an array of %d values", at, n_cols);
    const cJSON *v = row->child;
    int rc;
    if ((rc = pair_index(v, at, &r->i, err))) return rc;
    if ((rc = pair_index(v->next, at, &r->j, err))) return rc;
    /* n, sl2, sl2_m2, sl2sq, sl2sq_m2, rank, rank_m2, auc, cd, then the
     * geodesic ones (null when the cell has none) */
    double x[TCB_N_PAIR_COLUMNS - 2];
    for (int k = 0; k < TCB_N_PAIR_COLUMNS - 2; k++) x[k] = NAN;
    int k = 0;
    for (v = v->next->next; v; v = v->next, k++)
        if ((rc = value_or_null(v, at, &x[k], err))) return rc;
    if (!(x[0] >= 0)) return tcb_fail(err, TCB_ERR_INPUT, "%s: n must be >= 0", at);
    r->sl2 = (tcb_stat){x[0], x[1], x[2]};
    r->sl2sq = (tcb_stat){x[0], x[3], x[4]};
    r->rank = (tcb_stat){x[0], x[5], x[6]};
    r->auc = x[7];
    r->cd = x[8];
    return pair_geodesic(x, x[0], at, r, err);
}

static int load_pairs(const cJSON *root, int n_cols, const char *where, tcb_cell_result *c,
                      tcb_error *err)
{
    const cJSON *rows = cJSON_GetObjectItemCaseSensitive(root, "pairs");
    if (!cJSON_IsArray(rows))
        return tcb_fail(err, TCB_ERR_INPUT, "%s.pairs: expected an array", where);
    if (cJSON_GetArraySize(rows) != c->n_pairs)
        return tcb_fail(err, TCB_ERR_INPUT, "%s.pairs: %d rows, but split.n_pairs is %d", where,
                        cJSON_GetArraySize(rows), c->n_pairs);
    if (c->n_pairs == 0) return TCB_OK;
    c->pairs = calloc((size_t)c->n_pairs, sizeof *c->pairs);
    if (!c->pairs) return tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", where);
    int p = 0;
    for (const cJSON *row = rows->child; row; row = row->next, p++) {
        char at[TCB_ERRMSG_MAX];
        key_path(at, sizeof at, "%s.pairs[%d]", where, p);
        int rc = load_pair(row, n_cols, at, &c->pairs[p], err);
        if (rc) return rc;
    }
    return TCB_OK;
}

/* A clip's row: [start, corr, [err_1, …, err_16]] and, with the
 * corr_mesh column (n_cols 4), its value. */
static int load_clip(const cJSON *row, int n_cols, const char *at, tcb_clip_record *r, tcb_error *err)
{
    const int n_err = TCB_CLIP_FRAMES - 1;
    const cJSON *e = cJSON_IsArray(row) && cJSON_GetArraySize(row) == n_cols ? row->child->next->next : NULL;
    if (!e || !cJSON_IsArray(e) || cJSON_GetArraySize(e) != n_err)
        return tcb_fail(err, TCB_ERR_INPUT, "%s: expected [start, corr, [%d errors]%s]", at, n_err,
                        n_cols == 4 ? ", corr_mesh" : "");
    int rc = pair_index(row->child, at, &r->start, err);
    if (!rc) rc = value_or_null(row->child->next, at, &r->corr, err);
    int t = 0;
    for (const cJSON *v = e->child; v && !rc; v = v->next, t++) rc = value_or_null(v, at, &r->err[t], err);
    r->corr_mesh = NAN;
    if (!rc && n_cols == 4) rc = value_or_null(e->next, at, &r->corr_mesh, err);
    return rc;
}

/* The optional "clips" (none: n_clips 0). */
static int load_clips(const cJSON *root, const char *where, tcb_cell_result *c, tcb_error *err)
{
    if (!cJSON_HasObjectItem(root, "clips")) return TCB_OK;
    static const char *const columns[] = {"start", "corr", "err", "corr_mesh", NULL};
    char sub[TCB_ERRMSG_MAX];
    const cJSON *o, *cols, *rows;
    long long v;
    int rc = object_key(root, "clips", where, CLIPS_KEYS, &o, sub, sizeof sub, err);
    if (rc || (rc = copy_str(o, "path", sub, c->clips_path, sizeof c->clips_path, err)) ||
        (rc = tcb_json_int(o, "seed", sub, 1, 0, 0, (long long)TCB_JSON_INT_MAX, &v, err)))
        return rc;
    c->clips_seed = (unsigned long long)v;
    if ((rc = tcb_json_int(o, "clip_frames", sub, 1, 0, TCB_CLIP_FRAMES, TCB_CLIP_FRAMES, &v, err)) ||
        (rc = tcb_json_int(o, "n_clips", sub, 1, 0, 1, INT_MAX, &v, err)))
        return rc;
    cols = cJSON_GetObjectItemCaseSensitive(o, "columns");
    int k = 0, n_cols = cJSON_GetArraySize(cols), ok = cJSON_IsArray(cols) && (n_cols == 3 || n_cols == 4);
    for (const cJSON *e = ok ? cols->child : NULL; e; e = e->next, k++)
        ok = ok && cJSON_IsString(e) && !strcmp(e->valuestring, columns[k]);
    if (!ok)
        return tcb_fail(err, TCB_ERR_INPUT, "%s.columns: expected [\"start\", \"corr\", \"err\"] or with \"corr_mesh\"",
                        sub);
    rows = cJSON_GetObjectItemCaseSensitive(o, "rows");
    if (!cJSON_IsArray(rows) || cJSON_GetArraySize(rows) != v)
        return tcb_fail(err, TCB_ERR_INPUT, "%s.rows: expected an array of n_clips (%lld) rows", sub, v);
    c->clips = calloc((size_t)v, sizeof *c->clips);
    if (!c->clips) return tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", sub);
    c->n_clips = (int)v;
    k = 0;
    for (const cJSON *row = rows->child; row && !rc; row = row->next, k++) {
        char at[TCB_ERRMSG_MAX];
        key_path(at, sizeof at, "%s.rows[%d]", sub, k);
        rc = load_clip(row, n_cols, at, &c->clips[k], err);
    }
    return rc;
}

/* The "surface" columns: "frame", then tcb_recon_names in order. */
static int surface_columns_ok(const cJSON *cols)
{
    int k = 0, ok = cJSON_IsArray(cols) && cJSON_GetArraySize(cols) == TCB_N_RECON + 1;
    for (const cJSON *e = ok ? cols->child : NULL; e; e = e->next, k++)
        ok = ok && cJSON_IsString(e) && !strcmp(e->valuestring, k ? tcb_recon_names[k - 1] : "frame");
    return ok;
}

/* A surface row: [frame, cdl2, nc, fscore05, fscore1]. */
static int load_surface_row(const cJSON *row, const char *at, tcb_surface_record *r, tcb_error *err)
{
    if (!cJSON_IsArray(row) || cJSON_GetArraySize(row) != TCB_N_RECON + 1)
        return tcb_fail(err, TCB_ERR_INPUT, "%s: expected [frame, %d values]", at, TCB_N_RECON);
    int rc = pair_index(row->child, at, &r->frame, err), m = 0;
    for (const cJSON *v = row->child->next; v && !rc; v = v->next, m++) rc = value_or_null(v, at, &r->v[m], err);
    return rc;
}

/* The optional "surface" (none: n_surface 0). */
static int load_surface(const cJSON *root, const char *where, tcb_cell_result *c, tcb_error *err)
{
    if (!cJSON_HasObjectItem(root, "surface")) return TCB_OK;
    char sub[TCB_ERRMSG_MAX];
    const cJSON *o, *rows;
    long long v;
    int rc = object_key(root, "surface", where, SURFACE_KEYS, &o, sub, sizeof sub, err);
    if (rc || (rc = tcb_json_int(o, "samples", sub, 1, 0, 1, INT_MAX, &v, err))) return rc;
    c->surface_samples = (int)v;
    int frame;
    if ((rc = tcb_json_enum(o, "frame", sub, 0, TCB_RECON_FRAME_SEQUENCE, tcb_recon_frame_names, &frame, err)))
        return rc;
    c->surface_frame = (tcb_recon_frame)frame;
    if (!surface_columns_ok(cJSON_GetObjectItemCaseSensitive(o, "columns")))
        return tcb_fail(err, TCB_ERR_INPUT, "%s.columns: expected [\"frame\", \"cdl2\", \"nc\", \"fscore05\", \"fscore1\"]",
                        sub);
    rows = cJSON_GetObjectItemCaseSensitive(o, "rows");
    if (!cJSON_IsArray(rows) || cJSON_GetArraySize(rows) < 1)
        return tcb_fail(err, TCB_ERR_INPUT, "%s.rows: expected an array of one row per evaluated frame", sub);
    c->n_surface = cJSON_GetArraySize(rows);
    c->surface = calloc((size_t)c->n_surface, sizeof *c->surface);
    if (!c->surface) return tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", sub);
    int k = 0;
    for (const cJSON *row = rows->child; row && !rc; row = row->next, k++) {
        char at[TCB_ERRMSG_MAX];
        key_path(at, sizeof at, "%s.rows[%d]", sub, k);
        rc = load_surface_row(row, at, &c->surface[k], err);
        if (!rc && k > 0 && c->surface[k].frame <= c->surface[k - 1].frame)
            rc = tcb_fail(err, TCB_ERR_INPUT, "%s: frame %d after frame %d (ascending, each once)", at,
                          c->surface[k].frame, c->surface[k - 1].frame);
    }
    return rc;
}

static int load_params(const cJSON *root, const char *where, tcb_cell_result *c, tcb_error *err)
{
    char sub[TCB_ERRMSG_MAX];
    key_path(sub, sizeof sub, "%s.params", where);
    const cJSON *params = cJSON_GetObjectItemCaseSensitive(root, "params");
    if (!params) return tcb_fail(err, TCB_ERR_INPUT, "%s: missing key", sub);
    int rc = tcb_json_expect_object(params, sub, err);
    if (rc) return rc;
    char *text = cJSON_PrintUnformatted(params);
    c->params_json = text ? strdup(text) : NULL;
    cJSON_free(text);
    return c->params_json ? TCB_OK : tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", sub);
}

static int load_header(const cJSON *root, const char *where, tcb_cell_result *c, tcb_error *err)
{
    const char *format;
    int idx, rc;
    long long v;
    if ((rc = tcb_json_str(root, "format", where, 1, NULL, &format, err))) return rc;
    if (strcmp(format, TCB_CELL_FORMAT))
        return tcb_fail(err, TCB_ERR_INPUT, "%s.format: \"%s\" is not \"%s\"", where, format,
                        TCB_CELL_FORMAT);
    if ((rc = tcb_json_expect_keys(root, where, TOP_KEYS, err)) ||
        (rc = copy_str(root, "dataset", where, c->dataset, sizeof c->dataset, err)) ||
        (rc = copy_str(root, "sequence", where, c->sequence, sizeof c->sequence, err)) ||
        (rc = tcb_json_enum(root, "role", where, 1, 0, tcb_cell_role_names, &idx, err)))
        return rc;
    strcpy(c->role, tcb_cell_role_names[idx]);
    if ((rc = copy_str(root, "method", where, c->method, sizeof c->method, err)) ||
        (rc = copy_str(root, "method_impl", where, c->method_impl, sizeof c->method_impl, err)) ||
        (rc = tcb_json_int(root, "seed", where, 1, 0, INT_MIN, INT_MAX, &v, err)))
        return rc;
    c->seed = (int)v;
    if ((rc = tcb_json_enum(root, "status", where, 1, 0, tcb_cell_status_names, &idx, err)))
        return rc;
    c->status = (tcb_cell_status)idx;
    if ((rc = copy_str(root, "message", where, c->message, sizeof c->message, err)) ||
        (rc = copy_str(root, "git_revision", where, c->git_revision, sizeof c->git_revision,
                       err)) ||
        (rc = copy_str(root, "tcbench_version", where, c->tcbench_version,
                       sizeof c->tcbench_version, err)) ||
        (rc = tcb_json_int(root, "peak_rss_kb", where, 1, 0, 0, (long long)TCB_JSON_INT_MAX, &v,
                           err)))
        return rc;
    c->peak_rss_kb = (long)v;
    return TCB_OK;
}

static int load_timings_split(const cJSON *root, const char *where, tcb_cell_result *c,
                              tcb_error *err)
{
    char sub[TCB_ERRMSG_MAX];
    const cJSON *o;
    long long v;
    int rc;
    if ((rc = object_key(root, "timings", where, TIMING_KEYS, &o, sub, sizeof sub, err)) ||
        (rc = tcb_json_num(o, "load_s", sub, 1, 0, 0, INFINITY, &c->load_s, err)) ||
        (rc = tcb_json_num(o, "fit_s", sub, 1, 0, 0, INFINITY, &c->fit_s, err)) ||
        (rc = tcb_json_num(o, "eval_s", sub, 1, 0, 0, INFINITY, &c->eval_s, err)))
        return rc;
    if ((rc = object_key(root, "split", where, SPLIT_KEYS, &o, sub, sizeof sub, err)) ||
        (rc = copy_str(o, "path", sub, c->split_path, sizeof c->split_path, err)) ||
        (rc = tcb_json_int(o, "seed", sub, 1, 0, 0, (long long)TCB_JSON_INT_MAX, &v, err)))
        return rc;
    c->split_seed = (unsigned long long)v;
    if ((rc = tcb_json_int(o, "n_pairs", sub, 1, 0, 0, INT_MAX, &v, err))) return rc;
    c->n_pairs = (int)v;
    return TCB_OK;
}

/* "plugin", when the cell's method came from one (absent: built in, or a
 * cell written before the key). */
static int load_plugin(const cJSON *root, const char *where, tcb_cell_result *c, tcb_error *err)
{
    if (!cJSON_HasObjectItem(root, "plugin")) return TCB_OK;
    char sub[TCB_ERRMSG_MAX];
    const cJSON *o;
    long long v;
    int rc = object_key(root, "plugin", where, PLUGIN_KEYS, &o, sub, sizeof sub, err);
    if (rc || (rc = copy_str(o, "path", sub, c->plugin_path, sizeof c->plugin_path, err)) ||
        (rc = copy_str(o, "fnv1a64", sub, c->plugin_digest, sizeof c->plugin_digest, err)) ||
        (rc = tcb_json_int(o, "abi", sub, 1, 0, 1, INT_MAX, &v, err)) ||
        (rc = copy_str(o, "version", sub, c->plugin_version, sizeof c->plugin_version, err)))
        return rc;
    c->plugin_abi = (int)v;
    return TCB_OK;
}

/* "normals", when the method took normals with its points (absent: none,
 * or a cell written before the key). */
static int load_normals(const cJSON *root, const char *where, tcb_cell_result *c, tcb_error *err)
{
    if (!cJSON_HasObjectItem(root, "normals")) return TCB_OK;
    int idx;
    int rc = tcb_json_enum(root, "normals", where, 1, 0, NORMALS_NAMES, &idx, err);
    if (!rc) snprintf(c->normals, sizeof c->normals, "%s", NORMALS_NAMES[idx]);
    return rc;
}

/* "faces": false, when the sequence has none (absent: it has faces, or a
 * cell written before the key). */
static int load_faces(const cJSON *root, const char *where, tcb_cell_result *c, tcb_error *err)
{
    int faces;
    int rc = tcb_json_bool(root, "faces", where, 0, 1, &faces, err);
    if (!rc) c->no_faces = !faces;
    return rc;
}

static int cell_from_json(const cJSON *root, const char *path, tcb_cell_result *c,
                          tcb_error *err)
{
    int n_cols;
    int rc = tcb_json_expect_object(root, path, err);
    if (rc || (rc = load_header(root, path, c, err)) || (rc = load_plugin(root, path, c, err)) ||
        (rc = load_normals(root, path, c, err)) || (rc = load_faces(root, path, c, err)) ||
        (rc = load_params(root, path, c, err)) ||
        (rc = load_timings_split(root, path, c, err)) ||
        (rc = load_summary(root, path, &c->summary, err)) ||
        (rc = load_pair_columns(root, path, &n_cols, err)) ||
        (rc = load_pairs(root, n_cols, path, c, err)) || (rc = load_clips(root, path, c, err)) ||
        (rc = load_surface(root, path, c, err)))
        return rc;
    /* The summary's reconstruction metrics are over the cell's surface rows. */
    for (int m = 0; m < TCB_N_RECON; m++)
        if (c->summary.recon[m].n != c->n_surface)
            return tcb_fail(err, TCB_ERR_INPUT, "%s.summary.%s: over %g frames, but the cell has %d surface rows",
                            path, tcb_recon_names[m], c->summary.recon[m].n, c->n_surface);
    /* The summary's Corr is over the cell's clips, and only with clips. */
    if ((c->status == TCB_CELL_OK || c->n_clips == 0) && c->summary.corr.n != c->n_clips)
        return tcb_fail(err, TCB_ERR_INPUT, "%s.summary.corr: %s, but the cell has %d clips", path,
                        c->summary.corr.n > 0 ? "over other clips" : "absent", c->n_clips);
    int with_mesh = 0;
    for (int k = 0; k < c->n_clips; k++) with_mesh += !isnan(c->clips[k].corr_mesh);
    if (c->summary.corr_mesh.n != with_mesh)
        return tcb_fail(err, TCB_ERR_INPUT, "%s.summary.corr_mesh: over %g clips, but %d clips have it", path,
                        c->summary.corr_mesh.n, with_mesh);
    /* A finished ok cell scored every pair of its split. */
    if (c->status == TCB_CELL_OK && c->summary.n_pairs != c->n_pairs)
        return tcb_fail(err, TCB_ERR_INPUT, "%s.summary.n_pairs: %d, but the cell has %d pairs",
                        path, c->summary.n_pairs, c->n_pairs);
    return TCB_OK;
}

/* The JSON helpers join `where` and a key with '.'; at the top level that
 * reads "seed_0.json.status", so make it "seed_0.json: status". */
static void fix_top(const char *path, tcb_error *err)
{
    size_t n = strlen(path);
    if (!err || strncmp(err->msg, path, n) || err->msg[n] != '.') return;
    char rest[TCB_ERRMSG_MAX];
    snprintf(rest, sizeof rest, "%s", err->msg + n + 1);
    key_path(err->msg, sizeof err->msg, "%s: %s", path, rest);
}

int tcb_cell_load(const char *path, tcb_cell_result *out, tcb_error *err)
{
    memset(out, 0, sizeof *out);
    cJSON *root;
    int rc = tcb_json_load(path, &root, err);
    if (rc) return rc;
    rc = cell_from_json(root, path, out, err);
    cJSON_Delete(root);
    if (rc) {
        fix_top(path, err);
        tcb_cell_free(out);
    }
    return rc;
}
