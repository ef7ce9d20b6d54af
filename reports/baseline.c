/* Regression baselines: written from a run's table rows, read back strictly. */
#include "reports/baseline.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "tcb/json.h"
#include "tcb/report.h"

/* Deterministic methods must reproduce their numbers up to float noise; a
 * caller who wants slack for a stochastic method edits the file. */
#define DEFAULT_ABS_TOL 1e-6
#define DEFAULT_REL_TOL 1e-9

static const char *const STATUS_NAMES[] = {"ok", "failed", "diverged", NULL};
static const char *const TOP_KEYS[] = {"format", "tolerances", "rows", NULL};
static const char *const TOL_KEYS[] = {"abs", "rel", NULL};
static const char *const ROW_KEYS[] = {"dataset", "sequence", "method", "sl2",
                                       "rank",    "auc",      "cd",     "geo",
                                       "geo_auc", "corr",     "corr_mesh", "cdl2", "nc",
                                       "fscore05", "fscore1", "status",   "tolerances", NULL};

/* ----------------------------------------------------------------- write */

static int add_row(cJSON *rows, const tcb_rpt_block *b, const tcb_rpt_row *r)
{
    cJSON *o = cJSON_CreateObject();
    if (!o || !cJSON_AddItemToArray(rows, o)) {
        cJSON_Delete(o);
        return 0;
    }
    int ok = cJSON_AddStringToObject(o, "dataset", b->dataset) &&
             cJSON_AddStringToObject(o, "sequence", b->sequence) &&
             cJSON_AddStringToObject(o, "method", r->method);
    int is_ok = !strcmp(r->status, "ok");
    for (int m = 0; m < TCB_N_METRICS && ok; m++) {
        const char *key = tcb_rpt_metrics[m].key;
        ok = is_ok && r->has[m] ? cJSON_AddNumberToObject(o, key, r->mean[m]) != NULL
                                : cJSON_AddNullToObject(o, key) != NULL;
    }
    if (ok && !is_ok) ok = cJSON_AddStringToObject(o, "status", r->status) != NULL;
    return ok;
}

static cJSON *baseline_json(const tcb_rpt *r)
{
    cJSON *root = cJSON_CreateObject();
    cJSON *tol = cJSON_AddObjectToObject(root, "tolerances");
    int ok = root && cJSON_AddStringToObject(root, "format", TCB_BASELINE_FORMAT) && tol;
    for (int m = 0; m < TCB_N_METRICS && ok; m++) {
        cJSON *t = cJSON_AddObjectToObject(tol, tcb_rpt_metrics[m].key);
        ok = t && cJSON_AddNumberToObject(t, "abs", DEFAULT_ABS_TOL) &&
             cJSON_AddNumberToObject(t, "rel", DEFAULT_REL_TOL);
    }
    cJSON *rows = ok ? cJSON_AddArrayToObject(root, "rows") : NULL;
    ok = ok && rows;
    for (int k = 0; k < r->n_blocks && ok; k++)
        for (int i = 0; i < r->blocks[k].n_rows && ok; i++)
            ok = add_row(rows, &r->blocks[k], &r->blocks[k].rows[i]);
    if (!ok) {
        cJSON_Delete(root);
        return NULL;
    }
    return root;
}

/* {metric: {"abs", "rel"}} for the metrics whose tolerances differ from
 * (base_abs, base_rel), or every metric without a base; added to o as
 * "tolerances" when there is one. */
static int add_tolerances(cJSON *o, const double *abs_tol, const double *rel_tol, const double *base_abs,
                          const double *base_rel)
{
    cJSON *t = cJSON_CreateObject();
    int ok = t != NULL;
    for (int m = 0; m < TCB_N_METRICS && ok; m++) {
        if (base_abs && abs_tol[m] == base_abs[m] && rel_tol[m] == base_rel[m]) continue;
        cJSON *mt = cJSON_AddObjectToObject(t, tcb_rpt_metrics[m].key);
        ok = mt && cJSON_AddNumberToObject(mt, "abs", abs_tol[m]) && cJSON_AddNumberToObject(mt, "rel", rel_tol[m]);
    }
    if (ok && !t->child) {
        cJSON_Delete(t);
        return 1;
    }
    cJSON_DeleteItemFromObjectCaseSensitive(o, "tolerances");
    ok = ok && cJSON_AddItemToObject(o, "tolerances", t);
    if (!ok) cJSON_Delete(t);
    return ok;
}

/* The tolerances a person set in the baseline being rewritten: the file's
 * and each row's own, for the rows the run still has. A rewrite that
 * dropped them made the trained rows of tests/baselines/quick.json exact
 * at one thread count. */
static int keep_tolerances(cJSON *root, const tcb_baseline *old)
{
    int ok = add_tolerances(root, old->abs_tol, old->rel_tol, NULL, NULL);
    for (cJSON *o = cJSON_GetObjectItemCaseSensitive(root, "rows")->child; o && ok; o = o->next) {
        const char *d = cJSON_GetObjectItemCaseSensitive(o, "dataset")->valuestring,
                   *s = cJSON_GetObjectItemCaseSensitive(o, "sequence")->valuestring,
                   *m = cJSON_GetObjectItemCaseSensitive(o, "method")->valuestring;
        for (int k = 0; k < old->n_rows; k++) {
            const tcb_baseline_row *r = &old->rows[k];
            if (!strcmp(r->dataset, d) && !strcmp(r->sequence, s) && !strcmp(r->method, m))
                ok = add_tolerances(o, r->abs_tol, r->rel_tol, old->abs_tol, old->rel_tol);
        }
    }
    return ok;
}

int tcb_baseline_write(const char *run_dir, const char *baseline_path, tcb_error *err)
{
    tcb_baseline old = {0};
    int has_old = access(baseline_path, F_OK) == 0;
    if (has_old && tcb_baseline_load(baseline_path, &old, err)) {
        tcb_error_prefix(err, "cannot keep the tolerances of the baseline it replaces (remove it to write a new one): ");
        return err->code;
    }
    tcb_rpt r;
    int rc = tcb_rpt_load(run_dir, &r, err);
    cJSON *root = rc ? NULL : baseline_json(&r);
    if (!rc) tcb_rpt_free(&r);
    if (!rc && (!root || (has_old && !keep_tolerances(root, &old))))
        rc = tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", baseline_path);
    if (!rc) rc = tcb_json_save(baseline_path, root, err);
    cJSON_Delete(root);
    tcb_baseline_free(&old);
    return rc;
}

/* ------------------------------------------------------------------ load */

/* The tolerances object t ({metric: {"abs", "rel"}}) into abs_tol, rel_tol;
 * with `every`, each of the paper's metrics must be there (the top level),
 * else a metric left out keeps its value (a row's own tolerances, or the
 * default of a metric added since the baseline was written). */
static int parse_tolerances(const cJSON *t, const char *where, int every, double *abs_tol, double *rel_tol,
                            tcb_error *err)
{
    const char *keys[TCB_N_METRICS + 1] = {NULL};
    for (int m = 0; m < TCB_N_METRICS; m++) keys[m] = tcb_rpt_metrics[m].key;
    int rc = tcb_json_expect_keys(t, where, keys, err);
    for (int m = 0; m < TCB_N_METRICS && !rc; m++) {
        char sub[TCB_ERRMSG_MAX];
        snprintf(sub, sizeof sub, "%s.%s", where, keys[m]);
        const cJSON *o = cJSON_GetObjectItemCaseSensitive(t, keys[m]);
        if (!o && (!every || !tcb_rpt_metrics[m].paper)) continue;
        if (!o) return tcb_fail(err, TCB_ERR_INPUT, "%s: required key is missing", sub);
        if ((rc = tcb_json_expect_keys(o, sub, TOL_KEYS, err)) ||
            (rc = tcb_json_num(o, "abs", sub, 1, 0, 0, INFINITY, &abs_tol[m], err)))
            return rc;
        rc = tcb_json_num(o, "rel", sub, 1, 0, 0, INFINITY, &rel_tol[m], err);
    }
    return rc;
}

static int load_tolerances(const cJSON *root, const char *path, tcb_baseline *b, tcb_error *err)
{
    for (int m = 0; m < TCB_N_METRICS; m++) b->abs_tol[m] = DEFAULT_ABS_TOL, b->rel_tol[m] = DEFAULT_REL_TOL;
    char where[TCB_ERRMSG_MAX - 16]; /* room for ".<metric>" in sub */
    snprintf(where, sizeof where, "%s: tolerances", path);
    const cJSON *t = cJSON_GetObjectItemCaseSensitive(root, "tolerances");
    if (!t) return tcb_fail(err, TCB_ERR_INPUT, "%s: required key is missing", where);
    return parse_tolerances(t, where, 1, b->abs_tol, b->rel_tol, err);
}

static int copy_name(const cJSON *o, const char *key, const char *where, char *dst, size_t size,
                     tcb_error *err)
{
    const char *s;
    int rc = tcb_json_str(o, key, where, 1, NULL, &s, err);
    if (rc) return rc;
    if (!s[0] || strlen(s) >= size)
        return tcb_fail(err, TCB_ERR_INPUT, "%s.%s: must be 1 to %zu characters", where, key,
                        size - 1);
    memcpy(dst, s, strlen(s) + 1);
    return TCB_OK;
}

/* A row; its tolerances start as the file's (b) and may be its own. */
static int load_row(const cJSON *o, const char *where, const tcb_baseline *b, tcb_baseline_row *r, tcb_error *err)
{
    int st, rc;
    memcpy(r->abs_tol, b->abs_tol, sizeof r->abs_tol);
    memcpy(r->rel_tol, b->rel_tol, sizeof r->rel_tol);
    if ((rc = tcb_json_expect_keys(o, where, ROW_KEYS, err)) ||
        (rc = copy_name(o, "dataset", where, r->dataset, sizeof r->dataset, err)) ||
        (rc = copy_name(o, "sequence", where, r->sequence, sizeof r->sequence, err)) ||
        (rc = copy_name(o, "method", where, r->method, sizeof r->method, err)) ||
        (rc = tcb_json_enum(o, "status", where, 0, 0, STATUS_NAMES, &st, err)))
        return rc;
    snprintf(r->status, sizeof r->status, "%s", STATUS_NAMES[st]);
    for (int m = 0; m < TCB_N_METRICS; m++) {
        const char *key = tcb_rpt_metrics[m].key;
        const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
        if (!v && !tcb_rpt_metrics[m].paper) continue; /* not checked */
        if (!v) return tcb_fail(err, TCB_ERR_INPUT, "%s.%s: required key is missing", where, key);
        r->checked[m] = 1;
        if (!cJSON_IsNull(v) && !(cJSON_IsNumber(v) && isfinite(v->valuedouble)))
            return tcb_fail(err, TCB_ERR_INPUT, "%s.%s: expected a number or null", where, key);
        r->has[m] = cJSON_IsNumber(v);
        r->value[m] = r->has[m] ? v->valuedouble : NAN;
    }
    const cJSON *t = cJSON_GetObjectItemCaseSensitive(o, "tolerances");
    if (!t) return TCB_OK;
    char sub[TCB_ERRMSG_MAX - 32]; /* room for ".<metric>" after it */
    snprintf(sub, sizeof sub, "%s.tolerances", where);
    return parse_tolerances(t, sub, 0, r->abs_tol, r->rel_tol, err);
}

static int same_key(const tcb_baseline_row *a, const tcb_baseline_row *b)
{
    return !strcmp(a->dataset, b->dataset) && !strcmp(a->sequence, b->sequence) &&
           !strcmp(a->method, b->method);
}

static int load_rows(const cJSON *root, const char *path, tcb_baseline *b, tcb_error *err)
{
    const cJSON *rows = cJSON_GetObjectItemCaseSensitive(root, "rows");
    if (!cJSON_IsArray(rows))
        return tcb_fail(err, TCB_ERR_INPUT, "%s: rows: expected an array", path);
    int n = cJSON_GetArraySize(rows);
    b->rows = calloc(n ? (size_t)n : 1, sizeof *b->rows);
    if (!b->rows) return tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", path);
    for (const cJSON *o = rows->child; o; o = o->next) {
        char where[TCB_ERRMSG_MAX - 64]; /* room for ".tolerances.<metric>" after it */
        snprintf(where, sizeof where, "%s: rows[%d]", path, b->n_rows);
        tcb_baseline_row *r = &b->rows[b->n_rows];
        int rc = load_row(o, where, b, r, err);
        if (rc) return rc;
        for (int k = 0; k < b->n_rows; k++)
            if (same_key(&b->rows[k], r))
                return tcb_fail(err, TCB_ERR_INPUT, "%s: repeats rows[%d] (%s/%s/%s)", where, k,
                                r->dataset, r->sequence, r->method);
        b->n_rows++;
    }
    return TCB_OK;
}

/* A /1 file's CD-L2 was ×1e3; the tables print ×1e5 now. */
static void cdl2_from_v1(tcb_baseline *b)
{
    const double to_v2 = 100.0;
    b->abs_tol[TCB_M_CDL2] *= to_v2;
    for (int k = 0; k < b->n_rows; k++) {
        tcb_baseline_row *r = &b->rows[k];
        r->abs_tol[TCB_M_CDL2] *= to_v2;
        if (r->has[TCB_M_CDL2]) r->value[TCB_M_CDL2] *= to_v2;
    }
}

static int baseline_from_json(const cJSON *root, const char *path, tcb_baseline *b,
                              tcb_error *err)
{
    int rc = tcb_json_expect_object(root, path, err);
    if (rc) return rc;
    const cJSON *format = cJSON_GetObjectItemCaseSensitive(root, "format");
    int v1 = cJSON_IsString(format) && !strcmp(format->valuestring, TCB_BASELINE_FORMAT_V1);
    if (!v1 && (!cJSON_IsString(format) || strcmp(format->valuestring, TCB_BASELINE_FORMAT)))
        return tcb_fail(err, TCB_ERR_INPUT, "%s: format: expected \"%s\" (or \"%s\")", path,
                        TCB_BASELINE_FORMAT, TCB_BASELINE_FORMAT_V1);
    for (const cJSON *item = root->child; item; item = item->next) {
        int known = 0;
        for (int k = 0; TOP_KEYS[k]; k++) known |= !strcmp(item->string, TOP_KEYS[k]);
        if (!known)
            return tcb_fail(err, TCB_ERR_INPUT,
                            "%s: %s: unknown key (expected format, tolerances, rows)", path,
                            item->string);
    }
    if ((rc = load_tolerances(root, path, b, err)) || (rc = load_rows(root, path, b, err))) return rc;
    if (v1) cdl2_from_v1(b);
    return TCB_OK;
}

int tcb_baseline_load(const char *path, tcb_baseline *out, tcb_error *err)
{
    memset(out, 0, sizeof *out);
    cJSON *root;
    int rc = tcb_json_load(path, &root, err);
    if (rc) return rc;
    rc = baseline_from_json(root, path, out, err);
    cJSON_Delete(root);
    if (rc) tcb_baseline_free(out);
    return rc;
}

void tcb_baseline_free(tcb_baseline *b)
{
    free(b->rows);
    memset(b, 0, sizeof *b);
}
