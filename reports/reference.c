/* Reading a reference file strictly: every key known, every number in its
 * place, errors naming the table and row. */
#include "reports/reference.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tcb/fsutil.h"
#include "tcb/json.h"

static const char *const TOP_KEYS[] = {"format", "name", "paper", "units", "methods", "tables", NULL};
static const char *const TABLE_KEYS[] = {"id", "title", "rows", NULL};
static const char *const ROW_KEYS[] = {"paper_row", "dataset", "sequence", "method", "sl2",
                                       "rank", "auc", "cd", "geo", "geo_auc", NULL};

static int copy(char *dst, size_t cap, const cJSON *o, const char *key, const char *where, tcb_error *err)
{
    const char *s;
    int rc = tcb_json_str(o, key, where, 1, NULL, &s, err);
    if (rc) return rc;
    if (!s[0] || strlen(s) >= cap)
        return tcb_fail(err, TCB_ERR_INPUT, "%s.%s: must be 1 to %zu characters", where, key, cap - 1);
    memcpy(dst, s, strlen(s) + 1);
    return TCB_OK;
}

/* "sl2": null | [mean, std] | [mean, null]; a metric not of the paper's
 * protocol (the geodesic error) may be left out, as null. */
static int parse_value(const cJSON *o, int m, const char *where, tcb_ref_row *r, tcb_error *err)
{
    const char *key = tcb_rpt_metrics[m].key;
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
    if (!v && !tcb_rpt_metrics[m].paper) return TCB_OK;
    if (!v) return tcb_fail(err, TCB_ERR_INPUT, "%s.%s: required key is missing", where, key);
    if (cJSON_IsNull(v)) return TCB_OK;
    const cJSON *mean = cJSON_GetArrayItem(v, 0), *std = cJSON_GetArrayItem(v, 1);
    if (!cJSON_IsArray(v) || cJSON_GetArraySize(v) != 2 || !cJSON_IsNumber(mean) ||
        !(cJSON_IsNumber(std) || cJSON_IsNull(std)))
        return tcb_fail(err, TCB_ERR_INPUT, "%s.%s: expected null or [mean, std] (std may be null)", where, key);
    r->has[m] = 1, r->mean[m] = mean->valuedouble;
    r->has_std[m] = cJSON_IsNumber(std), r->std[m] = r->has_std[m] ? std->valuedouble : 0;
    return TCB_OK;
}

static int parse_row(const cJSON *o, const char *where, tcb_ref_row *r, tcb_error *err)
{
    int rc = tcb_json_expect_keys(o, where, ROW_KEYS, err);
    if (!rc) rc = copy(r->paper_row, sizeof r->paper_row, o, "paper_row", where, err);
    if (!rc) rc = copy(r->dataset, sizeof r->dataset, o, "dataset", where, err);
    if (!rc) rc = copy(r->sequence, sizeof r->sequence, o, "sequence", where, err);
    if (!rc) rc = copy(r->method, sizeof r->method, o, "method", where, err);
    for (int m = 0; m < TCB_N_METRICS && !rc; m++) rc = parse_value(o, m, where, r, err);
    return rc;
}

static int parse_table(const cJSON *o, const char *where, tcb_ref_table *t, tcb_error *err)
{
    int rc = tcb_json_expect_keys(o, where, TABLE_KEYS, err);
    if (!rc) rc = copy(t->id, sizeof t->id, o, "id", where, err);
    if (!rc) rc = copy(t->title, sizeof t->title, o, "title", where, err);
    if (rc) return rc;
    const cJSON *rows = cJSON_GetObjectItemCaseSensitive(o, "rows");
    int n = cJSON_GetArraySize(rows);
    if (!cJSON_IsArray(rows) || n < 1)
        return tcb_fail(err, TCB_ERR_INPUT, "%s.rows: expected a non-empty array", where);
    t->rows = calloc((size_t)n, sizeof *t->rows);
    if (!t->rows) return tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", where);
    char w[640];
    for (int k = 0; k < n && !rc; k++) {
        snprintf(w, sizeof w, "%s.rows[%d]", where, k);
        rc = parse_row(cJSON_GetArrayItem(rows, k), w, &t->rows[k], err);
        t->n_rows = k + 1;
    }
    return rc;
}

static int parse_tables(const cJSON *root, const char *origin, tcb_reference *r, tcb_error *err)
{
    const cJSON *tables = cJSON_GetObjectItemCaseSensitive(root, "tables");
    int n = cJSON_GetArraySize(tables);
    if (!cJSON_IsArray(tables) || n < 1)
        return tcb_fail(err, TCB_ERR_INPUT, "%s: tables: expected a non-empty array", origin);
    r->tables = calloc((size_t)n, sizeof *r->tables);
    if (!r->tables) return tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", origin);
    char w[512];
    int rc = TCB_OK;
    for (int k = 0; k < n && !rc; k++) {
        snprintf(w, sizeof w, "%s: tables[%d]", origin, k);
        rc = parse_table(cJSON_GetArrayItem(tables, k), w, &r->tables[k], err);
        r->n_tables = k + 1;
        for (int j = 0; j < k && !rc; j++)
            if (!strcmp(r->tables[j].id, r->tables[k].id))
                rc = tcb_fail(err, TCB_ERR_INPUT, "%s.id: duplicate table '%s'", w, r->tables[k].id);
    }
    return rc;
}

int tcb_reference_parse(const char *text, const char *origin, tcb_reference *out, tcb_error *err)
{
    memset(out, 0, sizeof *out);
    cJSON *root;
    int rc = tcb_json_parse(text, origin, &root, err);
    if (rc) return rc;
    const char *top = origin; /* top-level keys read "<file>.format" */
    const char *format = NULL;
    rc = tcb_json_expect_object(root, origin, err);
    if (!rc) rc = tcb_json_expect_keys(root, origin, TOP_KEYS, err);
    if (!rc) rc = tcb_json_str(root, "format", top, 1, NULL, &format, err);
    if (!rc && strcmp(format, TCB_REFERENCE_FORMAT))
        rc = tcb_fail(err, TCB_ERR_INPUT, "%s: format: '%s', expected '%s'", origin, format, TCB_REFERENCE_FORMAT);
    if (!rc) rc = copy(out->name, sizeof out->name, root, "name", top, err);
    if (!rc) rc = copy(out->paper, sizeof out->paper, root, "paper", top, err);
    if (!rc) rc = parse_tables(root, origin, out, err);
    cJSON_Delete(root);
    if (rc) tcb_reference_free(out);
    return rc;
}

int tcb_reference_load(const char *name, tcb_reference *out, tcb_error *err)
{
    for (int k = 0; tcb_reference_builtin_names[k]; k++)
        if (!strcmp(tcb_reference_builtin_names[k], name)) {
            char origin[64];
            snprintf(origin, sizeof origin, "reference %s", name);
            return tcb_reference_parse(tcb_reference_builtin_texts[k], origin, out, err);
        }
    if (!strchr(name, '/') && !strstr(name, ".json")) {
        memset(out, 0, sizeof *out);
        return tcb_fail(err, TCB_ERR_INPUT, "--reference %s: no such built-in reference (built in: iccv21; or a file)",
                        name);
    }
    char *text;
    int rc = tcb_read_file(name, &text, NULL, err);
    if (rc) {
        memset(out, 0, sizeof *out);
        return rc;
    }
    rc = tcb_reference_parse(text, name, out, err);
    free(text);
    return rc;
}

const tcb_ref_table *tcb_reference_table(const tcb_reference *r, const char *id)
{
    for (int k = 0; k < r->n_tables; k++)
        if (!strcmp(r->tables[k].id, id)) return &r->tables[k];
    return NULL;
}

void tcb_reference_free(tcb_reference *r)
{
    for (int k = 0; k < r->n_tables; k++) free(r->tables[k].rows);
    free(r->tables);
    memset(r, 0, sizeof *r);
}
