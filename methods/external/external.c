/* external — a method in any language: tcbench exports the sequence as
 * NumPy files, runs the user's command to fit and then once for all the
 * pairs of the cell, and reads the predictions back (external.h has the
 * protocol, docs/adding-a-method.md the user's side of it). The harness
 * scores them like any built-in's: an external command that returns
 * nearest's points makes a cell bit-identical to nearest's. */
#include <stdlib.h>
#include <string.h>

#include <cjson/cJSON.h>

#include "methods/builtin.h"
#include "methods/external/external.h"
#include "tcb/json.h"

static void ext_destroy(void *self)
{
    ext_method *m = self;
    if (!m) return;
    for (int k = 0; m->command && k < m->n_command; k++) free(m->command[k]);
    free(m->command);
    free(m->python);
    free(m->pairs);
    free(m->ids);
    free(m);
}

static int ext_create(const char *params_json, void **self, tcb_error *err)
{
    ext_method *m = calloc(1, sizeof *m);
    if (!m) return tcb_fail(err, TCB_ERR_NOMEM, "external: out of memory");
    int rc = ext_params_parse(params_json, m, err);
    if (rc) {
        ext_destroy(m);
        return rc;
    }
    *self = m;
    return TCB_OK;
}

static int ext_fit(void *self, const tcb_sequence *seq, const tcb_fit_ctx *ctx, tcb_error *err)
{
    ext_method *m = self;
    m->n_frames = seq->n_frames, m->n_verts = seq->n_verts;
    int rc = ext_set_work(m, ctx, err);
    if (!rc) rc = ext_export_sequence(m, seq, err);
    if (!rc) rc = ext_write_manifest(m, seq, ctx, "fit", err);
    if (!rc) rc = ext_run_step(m, "fit", ctx, err);
    return rc;
}

/* The checkpoint is a marker, not a model: the command keeps its model in
 * model/ itself. The marker says that fit finished, for this command and a
 * sequence of these sizes, so a resumed run, or inspect, goes straight to
 * the transfer step instead of refitting. */
static cJSON *marker(const ext_method *m, int n_frames, int n_verts)
{
    cJSON *o = cJSON_CreateObject();
    cJSON *cmd = cJSON_CreateStringArray((const char *const *)m->command, m->n_command);
    if (!o || !cmd || !cJSON_AddItemToObject(o, "command", cmd)) {
        cJSON_Delete(o);
        cJSON_Delete(cmd);
        return NULL;
    }
    if (cJSON_AddNumberToObject(o, "external_fit", EXT_PROTOCOL) && cJSON_AddNumberToObject(o, "n_frames", n_frames) &&
        cJSON_AddNumberToObject(o, "n_verts", n_verts))
        return o;
    cJSON_Delete(o);
    return NULL;
}

static int ext_save(void *self, const char *path, tcb_error *err)
{
    ext_method *m = self;
    cJSON *o = marker(m, m->n_frames, m->n_verts);
    int rc = o ? tcb_json_save(path, o, err) : tcb_fail(err, TCB_ERR_NOMEM, "external: out of memory");
    cJSON_Delete(o);
    return rc;
}

static int ext_load(void *self, const tcb_sequence *seq, const char *path, tcb_error *err)
{
    ext_method *m = self;
    cJSON *saved, *want = marker(m, seq->n_frames, seq->n_verts);
    int rc = want ? tcb_json_load(path, &saved, err) : tcb_fail(err, TCB_ERR_NOMEM, "external: out of memory");
    if (rc) {
        cJSON_Delete(want);
        return rc;
    }
    if (!cJSON_Compare(saved, want, 1))
        rc = tcb_fail(err, TCB_ERR_INPUT, "%s: the fit it marks was made by another command or on another sequence", path);
    cJSON_Delete(saved);
    cJSON_Delete(want);
    m->n_frames = seq->n_frames, m->n_verts = seq->n_verts;
    m->exported = 0; /* the files of this process's sequence are written again before the transfer step */
    return rc;
}

/* The batch's pairs and the scratch its transfers need. */
static int start_batch(ext_method *m, const tcb_sequence *seq, const int *pairs, int first, int n, tcb_error *err)
{
    free(m->pairs);
    free(m->ids);
    m->pairs = malloc((size_t)n * 2 * sizeof *m->pairs);
    m->ids = malloc((size_t)seq->n_verts * sizeof *m->ids);
    m->first = first, m->n = 0, m->next = 0, m->has_recon = 0;
    if (!m->pairs || !m->ids) return tcb_fail(err, TCB_ERR_NOMEM, "external: out of memory for %d pairs", n);
    memcpy(m->pairs, pairs, (size_t)n * 2 * sizeof *m->pairs);
    m->n = n;
    return TCB_OK;
}

/* pred/ emptied: a file left by an earlier run is never taken for this one's. */
static int clear_outputs(const ext_method *m, tcb_error *err)
{
    char dir[TCB_PATH_MAX];
    int rc = ext_path(m, EXT_PRED_DIR, dir, err);
    if (!rc) rc = tcb_empty_dir(dir, err);
    if (!rc) rc = tcb_mkdirs(dir, err);
    return rc;
}

/* The transfer step, for all the pairs at once. */
static int ext_prepare_pairs(void *self, const tcb_sequence *seq, const int *pairs, int first, int n,
                             const tcb_fit_ctx *ctx, tcb_error *err)
{
    ext_method *m = self;
    int rc = start_batch(m, seq, pairs, first, n, err);
    if (!rc) rc = ext_set_work(m, ctx, err);
    if (!rc && !m->exported) rc = ext_export_sequence(m, seq, err);
    if (!rc) rc = ext_export_pairs(m, err);
    if (!rc) rc = clear_outputs(m, err);
    if (!rc) rc = ext_write_manifest(m, seq, ctx, "transfer", err);
    if (!rc) rc = ext_run_step(m, "transfer", ctx, err);
    if (!rc) rc = ext_name_program(m, ext_check_outputs(m, err), err);
    if (rc) m->n = 0;
    return rc;
}

/* Batch pair b is (i, j): the harness keeps to the announced order. */
static int check_pair(const ext_method *m, int b, int i, int j, tcb_error *err)
{
    if (b >= 0 && b < m->n && m->pairs[2 * b] == i && m->pairs[2 * b + 1] == j) return TCB_OK;
    return tcb_fail(err, TCB_ERR_INTERNAL, "external: pair %d->%d is not the one prepare_pairs announced next", i, j);
}

static int ext_transfer(void *self, const tcb_sequence *seq, int i, int j, const float *src, int n, float *out,
                        tcb_rng *rng, tcb_error *err)
{
    (void)src, (void)rng;
    ext_method *m = self;
    if (n != seq->n_verts)
        return tcb_fail(err, TCB_ERR_INTERNAL, "external: transfers whole frames (%d points, not %d)", seq->n_verts, n);
    int rc = check_pair(m, m->next, i, j, err);
    if (rc) return rc;
    return ext_name_program(m, ext_read_transfer(m, seq, m->next++, out, err), err);
}

static int ext_reconstruct(void *self, const tcb_sequence *seq, int i, int j, int frame, tcb_rng *rng, float **pts,
                           int *n, tcb_error *err)
{
    (void)seq, (void)rng;
    ext_method *m = self;
    *pts = NULL, *n = 0;
    if (!m->has_recon) return tcb_fail(err, TCB_ERR_UNSUPPORTED, "external: the command wrote no reconstructions");
    int rc = check_pair(m, m->next - 1, i, j, err);
    return rc ? rc : ext_name_program(m, ext_read_recon(m, m->next - 1, frame == i ? 'i' : 'j', pts, n, err), err);
}

const tcb_method_ops tcb_method_external = {
    .abi_version = TCB_METHOD_ABI_VERSION,
    .name = "external",
    .description = "a method in any language: params.command run to fit, then once for all pairs (NumPy files)",
    .create = ext_create,
    .fit = ext_fit,
    .transfer = ext_transfer,
    .reconstruct = ext_reconstruct,
    .save = ext_save,
    .load = ext_load,
    .destroy = ext_destroy,
    .prepare_pairs = ext_prepare_pairs,
};
