/* `tcbench datasets align DIR`: the yaws the rotation alignment
 * (tcb/align.h) chooses for an OBJ directory, as a JSON file and a plot.
 * The authors' rots_120.npy and the script that made it were never
 * released; this writes the equivalent for any sequence.
 *
 * The frames are centred as TCB_NORM_PER_FRAME does (AMA's protocol) before
 * the angles are searched, exactly as a config with "align_rotation": true
 * loads them, so the file lists the rotations a run applies. */
#include <stdlib.h>

#include "cli/datasets.h"
#include "datasets/objdir.h"
#include "tcb/align.h"
#include "tcb/json.h"
#include "tcb/report.h"

/* {"format": "tcbench-rotations/1", "sequence", "directory", "normalization",
 *  "steps", "step_degrees", "samples", "seed",
 *  "frames": [{"frame", "file", "step", "yaw_degrees", "chamfer"}]} */
static cJSON *rotations_json(const char *dir, const tcb_sequence *s, const tcb_objdir_frame *files,
                             const int *step, const double *chamfer, int samples, uint64_t seed)
{
    cJSON *root = cJSON_CreateObject(), *frames = cJSON_CreateArray();
    cJSON_AddStringToObject(root, "format", "tcbench-rotations/1");
    cJSON_AddStringToObject(root, "sequence", s->name);
    cJSON_AddStringToObject(root, "directory", dir);
    cJSON_AddStringToObject(root, "normalization", "per_frame");
    cJSON_AddNumberToObject(root, "steps", TCB_ALIGN_STEPS);
    cJSON_AddNumberToObject(root, "step_degrees", 360.0 / TCB_ALIGN_STEPS);
    cJSON_AddNumberToObject(root, "samples", samples);
    cJSON_AddNumberToObject(root, "seed", (double)seed);
    cJSON_AddItemToObject(root, "frames", frames);
    for (int f = 0; f < s->n_frames; f++) {
        cJSON *o = cJSON_CreateObject();
        cJSON_AddNumberToObject(o, "frame", f);
        cJSON_AddStringToObject(o, "file", files[f].name);
        cJSON_AddNumberToObject(o, "step", step[f]);
        cJSON_AddNumberToObject(o, "yaw_degrees", step[f] * 360.0 / TCB_ALIGN_STEPS);
        cJSON_AddNumberToObject(o, "chamfer", chamfer[f]);
        cJSON_AddItemToArray(frames, o);
    }
    return root;
}

static int align_and_write(const char *dir, const tcb_objdir_frame *files, int n, const tcb_align_cmd *a,
                           tcb_sequence *s, int *step, double *chamfer, tcb_error *err)
{
    char name[TCB_NAME_MAX];
    int rc = tcb_objdir_default_name(dir, name, err);
    if (!rc) rc = tcb_objdir_read(dir, files, n, name, s, err);
    if (!rc) rc = tcb_sequence_normalize(s, TCB_NORM_PER_FRAME, err);
    if (!rc) rc = tcb_align_yaw(s, a->samples, a->seed, step, chamfer, err);
    if (rc) return rc;
    cJSON *json = rotations_json(dir, s, files, step, chamfer, a->samples, a->seed);
    rc = json ? tcb_json_save(a->out, json, err) : tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", a->out);
    cJSON_Delete(json);
    if (!rc && a->plot) rc = tcb_plot_yaw(a->plot, s->name, step, s->n_frames, a->samples, err);
    return rc;
}

int tcb_datasets_align(const char *dir, const tcb_align_cmd *a, tcb_error *err)
{
    tcb_objdir_frame *files;
    int n, rc = tcb_objdir_list(dir, &files, &n, err);
    if (rc) return rc;
    tcb_sequence s = {0};
    int *step = malloc((size_t)n * sizeof *step);
    double *chamfer = malloc((size_t)n * sizeof *chamfer);
    rc = step && chamfer ? align_and_write(dir, files, n, a, &s, step, chamfer, err)
                         : tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", dir);
    tcb_sequence_free(&s);
    free(files), free(step), free(chamfer);
    return rc;
}
