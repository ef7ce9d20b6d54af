/* Calibration files (costs/calibration.h): read, written, and found.
 *
 * {"format": "tcbench-calibration 1",
 *  "machine": {"summary": "CPU model, N cores", "cpu": ..., "cores": ..., ...},
 *  "sequence": {"name": "synth/quadruped_walk", "vertices": 1234, "frames": 6},
 *  "costs": [{"kind": "step", "method": "cc", "preset": "paper", "threads": 2,
 *             "seconds": 2.9, "samples": 4},
 *            {"kind": "unit", "method": "nricp", "preset": "", "unit": "assign", ...},
 *            {"kind": "unit", ..., "sequence": "ama/crane", "vertices": 10002},
 *            {"kind": "surface_frame", ..., "size": 100000},
 *            {"kind": "surface_mesh", ...}, ...]}
 * "unit" is there for kind unit only, "size" for surface_frame only,
 * "sequence" and "vertices" for a unit or a pair's scoring measured on a
 * config's sequence;
 * "frames" may be absent (files older than it: TCB_CALIBRATION_FRAMES). */
#include <stdlib.h>
#include <string.h>

#include "costs/calibration.h"
#include "tcb/fsutil.h"
#include "tcb/json.h"

#define FORMAT "tcbench-calibration 1"

static const char *const kind_names[] = {"step", "eval_pair", "score_pair", "unit", "surface_frame",
                                         "surface_mesh", NULL}; /* tcb_cost_kind */

extern const char *const tcb_calibration_builtin_names[];
extern const char *const tcb_calibration_builtin_texts[];

void tcb_calibration_free(tcb_calibration *c)
{
    free(c->machine_json);
    free(c->entries);
    memset(c, 0, sizeof *c);
}

int tcb_calibration_add(tcb_calibration *c, const tcb_cost_entry *e, tcb_error *err)
{
    if (c->n == c->cap) {
        int cap = c->cap ? 2 * c->cap : 32;
        tcb_cost_entry *grown = realloc(c->entries, (size_t)cap * sizeof *grown);
        if (!grown) return tcb_fail(err, TCB_ERR_NOMEM, "out of memory");
        c->entries = grown, c->cap = cap;
    }
    c->entries[c->n++] = *e;
    return TCB_OK;
}

static int copy_str(const cJSON *o, const char *key, const char *where, char *out, size_t size, tcb_error *err)
{
    const char *s;
    int rc = tcb_json_str(o, key, where, 1, NULL, &s, err);
    if (!rc && strlen(s) >= size) rc = tcb_fail(err, TCB_ERR_INPUT, "%s.%s: longer than %zu characters", where, key,
                                                size - 1);
    if (!rc) snprintf(out, size, "%s", s);
    return rc;
}

/* The sequence a unit or a pair's scoring was measured on and its vertex
 * count, both or neither. */
static int parse_sequence(const cJSON *o, const char *where, tcb_cost_entry *e, tcb_error *err)
{
    int has_seq = cJSON_GetObjectItemCaseSensitive(o, "sequence") != NULL;
    int has_verts = cJSON_GetObjectItemCaseSensitive(o, "vertices") != NULL;
    if (has_seq != has_verts)
        return tcb_fail(err, TCB_ERR_INPUT, "%s.%s: a cost measured on a sequence has both \"sequence\" and "
                        "\"vertices\"", where, has_seq ? "sequence" : "vertices");
    long long nv = 0;
    int rc = has_seq ? copy_str(o, "sequence", where, e->sequence, sizeof e->sequence, err) : TCB_OK;
    if (!rc && has_seq) rc = tcb_json_int(o, "vertices", where, 1, 0, 1, 100000000, &nv, err);
    e->vertices = (int)nv;
    return rc;
}

/* The keys only some kinds have: a unit's name, a surface frame's
 * samples, the sequence of a unit or a pair's scoring. */
static int parse_kind_keys(const cJSON *o, const char *where, tcb_cost_entry *e, tcb_error *err)
{
    if (e->kind == TCB_COST_UNIT || e->kind == TCB_COST_SCORE_PAIR) {
        int rc = e->kind == TCB_COST_UNIT ? copy_str(o, "unit", where, e->unit, sizeof e->unit, err) : TCB_OK;
        if (!rc && e->kind != TCB_COST_UNIT && cJSON_GetObjectItemCaseSensitive(o, "unit"))
            rc = tcb_fail(err, TCB_ERR_INPUT, "%s.unit: only a cost of kind \"unit\" has one", where);
        return rc ? rc : parse_sequence(o, where, e, err);
    }
    static const char *const keys[] = {"unit", "sequence", "vertices", NULL};
    for (int k = 0; keys[k]; k++)
        if (cJSON_GetObjectItemCaseSensitive(o, keys[k]))
            return tcb_fail(err, TCB_ERR_INPUT, "%s.%s: only a cost of kind \"%s\" has one", where, keys[k],
                            k ? "unit\" or \"score_pair" : "unit");
    long long size = 0;
    int surface = e->kind == TCB_COST_SURFACE_FRAME;
    if (!surface && cJSON_GetObjectItemCaseSensitive(o, "size"))
        return tcb_fail(err, TCB_ERR_INPUT, "%s.size: only a cost of kind \"surface_frame\" has one", where);
    int rc = surface ? tcb_json_int(o, "size", where, 1, 0, 1, 1 << 30, &size, err) : TCB_OK;
    e->size = (int)size;
    return rc;
}

static int parse_entry(const cJSON *o, const char *where, tcb_calibration *c, tcb_error *err)
{
    static const char *const keys[] = {"kind",    "method", "preset", "unit",     "threads", "seconds",
                                       "samples", "size",   "sequence", "vertices", NULL};
    tcb_cost_entry e = {0};
    int kind = 0;
    long long threads = 0, samples = 0;
    int rc = tcb_json_expect_keys(o, where, keys, err);
    if (!rc) rc = tcb_json_enum(o, "kind", where, 1, 0, kind_names, &kind, err);
    e.kind = (tcb_cost_kind)kind;
    if (!rc) rc = copy_str(o, "method", where, e.method, sizeof e.method, err);
    if (!rc) rc = copy_str(o, "preset", where, e.preset, sizeof e.preset, err);
    if (!rc) rc = parse_kind_keys(o, where, &e, err);
    if (!rc) rc = tcb_json_int(o, "threads", where, 1, 0, 1, 1 << 20, &threads, err);
    if (!rc) rc = tcb_json_num(o, "seconds", where, 1, 0, 1e-12, 1e9, &e.seconds, err);
    if (!rc) rc = tcb_json_int(o, "samples", where, 1, 0, 1, 1 << 30, &samples, err);
    if (rc) return rc;
    e.threads = (int)threads, e.samples = (int)samples;
    return tcb_calibration_add(c, &e, err);
}

static int parse_header(const cJSON *root, const char *origin, tcb_calibration *c, tcb_error *err)
{
    static const char *const keys[] = {"format", "machine", "sequence", "costs", NULL};
    const char *format;
    long long nv = 0, frames = 0;
    char where[4200];
    int rc = tcb_json_expect_keys(root, origin, keys, err);
    if (!rc) rc = tcb_json_str(root, "format", origin, 1, NULL, &format, err);
    if (!rc && strcmp(format, FORMAT))
        rc = tcb_fail(err, TCB_ERR_INPUT, "%s: format: expected \"%s\", got \"%s\"", origin, FORMAT, format);
    const cJSON *machine = cJSON_GetObjectItemCaseSensitive(root, "machine");
    const cJSON *seq = cJSON_GetObjectItemCaseSensitive(root, "sequence");
    snprintf(where, sizeof where, "%s: machine", origin);
    if (!rc) rc = tcb_json_expect_object(machine, where, err);
    if (!rc) rc = copy_str(machine, "summary", where, c->machine, sizeof c->machine, err);
    snprintf(where, sizeof where, "%s: sequence", origin);
    if (!rc) rc = tcb_json_expect_object(seq, where, err);
    if (!rc) rc = tcb_json_int(seq, "vertices", where, 1, 0, 1, 100000000, &nv, err);
    if (!rc) rc = tcb_json_int(seq, "frames", where, 0, TCB_CALIBRATION_FRAMES, 1, 100000000, &frames, err);
    if (rc) return rc;
    c->n_verts = (int)nv, c->n_frames = (int)frames;
    if (!(c->machine_json = cJSON_PrintUnformatted(machine))) return tcb_fail(err, TCB_ERR_NOMEM, "out of memory");
    return TCB_OK;
}

int tcb_calibration_parse(const char *text, const char *origin, tcb_calibration *out, tcb_error *err)
{
    memset(out, 0, sizeof *out);
    snprintf(out->origin, sizeof out->origin, "%s", origin);
    cJSON *root;
    int rc = tcb_json_parse(text, origin, &root, err);
    if (rc) return rc;
    rc = tcb_json_expect_object(root, origin, err);
    if (!rc) rc = parse_header(root, origin, out, err);
    const cJSON *costs = cJSON_GetObjectItemCaseSensitive(root, "costs");
    if (!rc && !cJSON_IsArray(costs)) rc = tcb_fail(err, TCB_ERR_INPUT, "%s: costs: expected an array", origin);
    int k = 0;
    const cJSON *e;
    cJSON_ArrayForEach(e, costs)
    {
        char where[4200];
        snprintf(where, sizeof where, "%s: costs[%d]", origin, k++);
        if (!rc) rc = tcb_json_expect_object(e, where, err);
        if (!rc) rc = parse_entry(e, where, out, err);
    }
    cJSON_Delete(root);
    if (rc) tcb_calibration_free(out);
    return rc;
}

/* x to 4 significant digits: what a timing is worth, and a readable file. */
static double significant(double x)
{
    char text[32];
    snprintf(text, sizeof text, "%.4g", x);
    return strtod(text, NULL);
}

static cJSON *entry_json(const tcb_cost_entry *e)
{
    cJSON *o = cJSON_CreateObject();
    if (!o) return NULL;
    cJSON_AddStringToObject(o, "kind", kind_names[e->kind]);
    cJSON_AddStringToObject(o, "method", e->method);
    cJSON_AddStringToObject(o, "preset", e->preset);
    if (e->kind == TCB_COST_UNIT) cJSON_AddStringToObject(o, "unit", e->unit);
    cJSON_AddNumberToObject(o, "threads", e->threads);
    cJSON_AddNumberToObject(o, "seconds", significant(e->seconds));
    cJSON_AddNumberToObject(o, "samples", e->samples);
    if (e->kind == TCB_COST_SURFACE_FRAME) cJSON_AddNumberToObject(o, "size", e->size);
    if (e->sequence[0]) cJSON_AddStringToObject(o, "sequence", e->sequence);
    if (e->sequence[0]) cJSON_AddNumberToObject(o, "vertices", e->vertices);
    return o;
}

int tcb_calibration_write(const tcb_calibration *c, const char *path, tcb_error *err)
{
    cJSON *root = cJSON_CreateObject(), *costs = cJSON_CreateArray();
    cJSON *machine = cJSON_Parse(c->machine_json ? c->machine_json : "{}"), *seq = cJSON_CreateObject();
    int ok = root && costs && machine && seq;
    if (ok) {
        cJSON_AddStringToObject(root, "format", FORMAT);
        cJSON_AddItemToObject(root, "machine", machine);
        cJSON_AddStringToObject(seq, "name", "synth/quadruped_walk");
        cJSON_AddNumberToObject(seq, "vertices", c->n_verts);
        cJSON_AddNumberToObject(seq, "frames", c->n_frames);
        cJSON_AddItemToObject(root, "sequence", seq);
        cJSON_AddItemToObject(root, "costs", costs);
        machine = seq = NULL;
    }
    for (int k = 0; ok && k < c->n; k++) {
        cJSON *e = entry_json(&c->entries[k]);
        ok = e && cJSON_AddItemToArray(costs, e);
    }
    if (!ok) cJSON_Delete(costs);
    cJSON_Delete(machine), cJSON_Delete(seq);
    int rc = ok ? tcb_json_save(path, root, err) : tcb_fail(err, TCB_ERR_NOMEM, "out of memory");
    cJSON_Delete(root);
    return rc;
}

int tcb_calibration_builtin(tcb_calibration *out, tcb_error *err)
{
    return tcb_calibration_parse(tcb_calibration_builtin_texts[0], "built-in", out, err);
}

void tcb_calibration_user_path(char *out, size_t size)
{
    const char *xdg = getenv("XDG_CONFIG_HOME"), *home = getenv("HOME");
    if (xdg && xdg[0]) snprintf(out, size, "%s/tcbench/calibration.json", xdg);
    else if (home && home[0]) snprintf(out, size, "%s/.config/tcbench/calibration.json", home);
    else if (size) out[0] = '\0';
}

/* Adds path's calibration to s when the file exists. */
static int load_if_present(const char *path, tcb_calibration_set *s, tcb_error *err)
{
    if (!path[0] || !tcb_is_file(path)) return TCB_OK;
    char *text;
    size_t len;
    int rc = tcb_read_file(path, &text, &len, err);
    if (rc) return rc;
    rc = tcb_calibration_parse(text, path, &s->c[s->n], err);
    free(text);
    if (!rc) s->n++;
    return rc;
}

int tcb_calibration_set_load(const char *run_dir, tcb_calibration_set *s, tcb_error *err)
{
    memset(s, 0, sizeof *s);
    char path[4096];
    int rc = tcb_path_join(path, sizeof path, err, "%s/calibration.json", run_dir);
    if (!rc) rc = load_if_present(path, s, err);
    tcb_calibration_user_path(path, sizeof path);
    if (!rc) rc = load_if_present(path, s, err);
    if (!rc) rc = tcb_calibration_builtin(&s->c[s->n], err);
    if (!rc) s->n++;
    if (rc) tcb_calibration_set_free(s);
    return rc;
}

void tcb_calibration_set_free(tcb_calibration_set *s)
{
    for (int k = 0; k < s->n; k++) tcb_calibration_free(&s->c[k]);
    s->n = 0;
}
