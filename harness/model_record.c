/* The record of a cell's model checkpoint, <checkpoint>.fit.json, written
 * before the checkpoint is published:
 *     {"cell": "synth/quadruped_walk/mca/seed 0", "method": "mca",
 *      "params": "<the params as JSON text>", "sequence": "<fingerprint>",
 *      "bytes": N, "fnv1a64": "<hex>", "fit_s": seconds}
 * A checkpoint is reused only when its record says it was made for this
 * cell (label, method, params, and the sequence as tcb_sequence_fingerprint
 * sees it) and the file still has the recorded size and hash: a truncated,
 * bit-flipped or foreign model (another cell's, another config's) is
 * refused with the reason, never loaded — a method's own file format need
 * not detect any of this. fit_s lets a rerun that reuses the checkpoint
 * (its evaluation was killed) report the fit's time instead of the moment
 * loading takes, so a cell's fit_s does not depend on where a run was
 * interrupted. */
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cjson/cJSON.h>

#include "harness/harness_internal.h"
#include "tcb/fsutil.h"
#include "tcb/hash.h"
#include "tcb/json.h"

static int record_path(const char *checkpoint, char *out, tcb_error *err)
{
    return tcb_path_join(out, TCB_PATH_MAX, err, "%s.fit.json", checkpoint);
}

/* What the record says of the cell and the sequence, as this job has them. */
typedef struct identity {
    char cell[TCB_CELL_LABEL_MAX];
    char sequence[17];
} identity;

static void identity_of(const tcb_cell_job *job, identity *id)
{
    tcb_cell_label(id->cell, sizeof id->cell, job->dataset->name, job->seq->name, job->method->label, job->seed);
    snprintf(id->sequence, sizeof id->sequence, "%016" PRIx64, tcb_sequence_fingerprint(job->seq));
}

int tcb_model_record_save(const tcb_cell_job *job, const char *saved, double fit_s, tcb_error *err)
{
    char path[TCB_PATH_MAX], hex[17];
    size_t bytes;
    identity id;
    int rc = record_path(job->checkpoint, path, err);
    if (!rc) rc = tcb_file_fnv1a64(saved, &bytes, hex, err);
    if (rc) return rc;
    identity_of(job, &id);
    cJSON *o = cJSON_CreateObject();
    int ok = o && cJSON_AddStringToObject(o, "cell", id.cell) &&
             cJSON_AddStringToObject(o, "method", job->ops->name) &&
             cJSON_AddStringToObject(o, "params", job->method->params_json) &&
             cJSON_AddStringToObject(o, "sequence", id.sequence) && cJSON_AddNumberToObject(o, "bytes", (double)bytes) &&
             cJSON_AddStringToObject(o, "fnv1a64", hex) && cJSON_AddNumberToObject(o, "fit_s", fit_s);
    rc = ok ? tcb_json_save(path, o, err) : tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", path);
    cJSON_Delete(o);
    return rc;
}

/* The record's string `key` equals `want`; else an error saying what it
 * was made for. */
static int expect_same(const cJSON *o, const char *key, const char *want, const char *path, tcb_error *err)
{
    const char *got;
    int rc = tcb_json_str(o, key, path, 1, NULL, &got, err);
    if (rc || strcmp(got, want) == 0) return rc;
    return tcb_fail(err, TCB_ERR_INPUT, "%s: made for %s %s, this cell has %s", path, key, got, want);
}

int tcb_model_record_check(const tcb_cell_job *job, double *fit_s, tcb_error *err)
{
    static const char *const keys[] = {"cell", "method", "params", "sequence", "bytes", "fnv1a64", "fit_s", NULL};
    char path[TCB_PATH_MAX], hex[17] = "";
    const char *want_hex = "";
    double want_bytes = 0;
    size_t bytes = 0;
    identity id;
    cJSON *o = NULL;
    identity_of(job, &id);
    int rc = record_path(job->checkpoint, path, err);
    if (!rc) rc = tcb_json_load(path, &o, err);
    if (!rc) rc = tcb_json_expect_keys(o, path, keys, err);
    if (!rc) rc = expect_same(o, "cell", id.cell, path, err);
    if (!rc) rc = expect_same(o, "method", job->ops->name, path, err);
    if (!rc) rc = expect_same(o, "params", job->method->params_json, path, err);
    if (!rc && (rc = expect_same(o, "sequence", id.sequence, path, err)))
        tcb_error_prefix(err, "another sequence or other dataset settings: ");
    if (!rc) rc = tcb_json_num(o, "bytes", path, 1, 0, 0, 1e18, &want_bytes, err);
    if (!rc) rc = tcb_json_str(o, "fnv1a64", path, 1, NULL, &want_hex, err);
    if (!rc) rc = tcb_json_num(o, "fit_s", path, 1, 0, 0, INFINITY, fit_s, err);
    if (!rc) rc = tcb_file_fnv1a64(job->checkpoint, &bytes, hex, err);
    if (!rc && (double)bytes != want_bytes)
        rc = tcb_fail(err, TCB_ERR_INPUT, "%s: %zu bytes, its record %s says %.0f (truncated or replaced)",
                      job->checkpoint, bytes, path, want_bytes);
    if (!rc && strcmp(hex, want_hex) != 0)
        rc = tcb_fail(err, TCB_ERR_INPUT, "%s: its bytes do not hash to what its record %s says (corrupted or replaced)",
                      job->checkpoint, path);
    cJSON_Delete(o);
    return rc;
}
