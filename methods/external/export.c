/* What tcbench writes for the command: the sequence as .npy files, the
 * pairs of a batch, and the manifest that names them with everything else
 * the command may need. The manifest is rewritten before every run of the
 * command, so it always describes the step being run. */
#include <limits.h>
#include <stdlib.h>
#include <string.h>

#include <cjson/cJSON.h>

#include "methods/external/external.h"
#include "tcb/json.h"
#include "tcb/npy.h"

int ext_path(const ext_method *m, const char *name, char *out, tcb_error *err)
{
    return tcb_path_join(out, TCB_PATH_MAX, err, "%s/%s", m->work, name);
}

/* Absolute, so the command may change its directory; the command itself
 * runs in tcbench's, where a relative path in params.command is meant. */
int ext_set_work(ext_method *m, const tcb_fit_ctx *ctx, tcb_error *err)
{
    char abs[PATH_MAX], model[TCB_PATH_MAX];
    if (!ctx->work_dir) return tcb_fail(err, TCB_ERR_INTERNAL, "external: the harness gave no work directory");
    if (!realpath(ctx->work_dir, abs)) return tcb_fail(err, TCB_ERR_IO, "%s: no such directory", ctx->work_dir);
    int rc = tcb_path_join(m->work, sizeof m->work, err, "%s", abs);
    if (!rc) rc = ext_path(m, EXT_MODEL_DIR, model, err);
    if (!rc) rc = tcb_mkdirs(model, err);
    return rc;
}

static int save_npy(const ext_method *m, const char *name, tcb_npy_dtype dtype, int ndim, const uint64_t *shape,
                    const void *data, tcb_error *err)
{
    char path[TCB_PATH_MAX];
    int rc = ext_path(m, name, path, err);
    return rc ? rc : tcb_npy_save(path, dtype, ndim, shape, data, err);
}

int ext_export_sequence(ext_method *m, const tcb_sequence *seq, tcb_error *err)
{
    const uint64_t frames[] = {(uint64_t)seq->n_frames, (uint64_t)seq->n_verts, 3};
    const uint64_t faces[] = {(uint64_t)seq->n_faces, 3};
    const uint64_t pools[] = {(uint64_t)seq->n_frames, (uint64_t)seq->pool_size, 3};
    int rc = save_npy(m, "frames.npy", TCB_NPY_F4, 3, frames, seq->verts, err);
    if (!rc) rc = save_npy(m, "faces.npy", TCB_NPY_I4, 2, faces, seq->faces, err);
    if (!rc && seq->pool_size > 0) rc = save_npy(m, "pools.npy", TCB_NPY_F4, 3, pools, seq->pools, err);
    if (!rc) m->exported = 1;
    return rc;
}

int ext_export_pairs(const ext_method *m, tcb_error *err)
{
    int32_t *rows = malloc((size_t)m->n * 3 * sizeof *rows);
    if (!rows) return tcb_fail(err, TCB_ERR_NOMEM, "external: out of memory for %d pairs", m->n);
    for (int b = 0; b < m->n; b++)
        rows[3 * b] = m->first + b, rows[3 * b + 1] = m->pairs[2 * b], rows[3 * b + 2] = m->pairs[2 * b + 1];
    const uint64_t shape[] = {(uint64_t)m->n, 3};
    int rc = save_npy(m, "pairs.npy", TCB_NPY_I4, 2, shape, rows, err);
    free(rows);
    return rc;
}

static int nomem(tcb_error *err) { return tcb_fail(err, TCB_ERR_NOMEM, "external: out of memory for the manifest"); }

/* The path of `name` in the work directory as a manifest entry. */
static int add_path(cJSON *o, const ext_method *m, const char *key, const char *name, tcb_error *err)
{
    char path[TCB_PATH_MAX];
    int rc = ext_path(m, name, path, err);
    if (!rc && !cJSON_AddStringToObject(o, key, path)) rc = nomem(err);
    return rc;
}

/* [{"name", "start", "n_frames"}, ...]; [] for a sequence of one block. */
static cJSON *blocks_json(const tcb_sequence *seq)
{
    cJSON *a = cJSON_CreateArray();
    for (int b = 0; a && b < seq->n_blocks; b++) {
        cJSON *o = cJSON_CreateObject();
        if (!o || !cJSON_AddItemToArray(a, o) || !cJSON_AddStringToObject(o, "name", seq->blocks[b].name) ||
            !cJSON_AddNumberToObject(o, "start", seq->blocks[b].start) ||
            !cJSON_AddNumberToObject(o, "n_frames", seq->blocks[b].n_frames)) {
            cJSON_Delete(a);
            return NULL;
        }
    }
    return a;
}

/* The step, the sequence's name, sizes and settings, the run's seed and
 * threads, its blocks; 0 when out of memory. */
static int add_description(cJSON *o, const char *step, const tcb_sequence *seq, const tcb_fit_ctx *ctx)
{
    const struct {
        const char *key;
        double value;
    } nums[] = {{"protocol", EXT_PROTOCOL},
                {"n_frames", seq->n_frames},
                {"n_verts", seq->n_verts},
                {"n_faces", seq->n_faces},
                {"pool_size", seq->pool_size},
                {"input_points", seq->input_points},
                {"seed", (double)ctx->seed},
                {"threads", ctx->n_threads}};
    if (!cJSON_AddStringToObject(o, "step", step) || !cJSON_AddStringToObject(o, "sequence", seq->name)) return 0;
    for (size_t k = 0; k < sizeof nums / sizeof nums[0]; k++)
        if (!cJSON_AddNumberToObject(o, nums[k].key, nums[k].value)) return 0;
    if (!cJSON_AddBoolToObject(o, "with_replacement", seq->draw_with_replacement)) return 0;
    cJSON *blocks = blocks_json(seq);
    if (blocks && cJSON_AddItemToObject(o, "blocks", blocks)) return 1;
    cJSON_Delete(blocks);
    return 0;
}

/* The files: sequence, model directory, log; with the pairs for transfer. */
static int add_files(cJSON *o, const ext_method *m, const tcb_sequence *seq, int transfer, tcb_error *err)
{
    int rc = add_path(o, m, "frames", "frames.npy", err);
    if (!rc) rc = add_path(o, m, "faces", "faces.npy", err);
    if (!rc && seq->pool_size > 0) rc = add_path(o, m, "pools", "pools.npy", err);
    else if (!rc && !cJSON_AddNullToObject(o, "pools")) rc = nomem(err);
    if (!rc) rc = add_path(o, m, "model_dir", EXT_MODEL_DIR, err);
    if (!rc) rc = add_path(o, m, "log", EXT_LOG, err);
    if (!rc && transfer) rc = add_path(o, m, "pairs", "pairs.npy", err);
    if (!rc && transfer) rc = add_path(o, m, "out_dir", EXT_PRED_DIR, err);
    if (!rc && transfer && !cJSON_AddNumberToObject(o, "n_pairs", m->n)) rc = nomem(err);
    return rc;
}

int ext_write_manifest(const ext_method *m, const tcb_sequence *seq, const tcb_fit_ctx *ctx, const char *step,
                       tcb_error *err)
{
    cJSON *o = cJSON_CreateObject();
    int rc = o && add_description(o, step, seq, ctx) ? TCB_OK : nomem(err);
    if (!rc) rc = add_files(o, m, seq, !strcmp(step, "transfer"), err);
    char path[TCB_PATH_MAX];
    if (!rc) rc = ext_path(m, EXT_MANIFEST, path, err);
    if (!rc) rc = tcb_json_save(path, o, err);
    cJSON_Delete(o);
    return rc;
}
