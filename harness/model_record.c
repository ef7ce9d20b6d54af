/* The record of what fitting a cell's model cost, kept beside its model
 * checkpoint as <checkpoint>.fit.json = {"fit_s": seconds}. A rerun that
 * reuses the checkpoint (its evaluation was killed) reports that fit time
 * instead of the fraction of a second it took to load the model, so a
 * cell's fit_s does not depend on where a run was interrupted. */
#include <math.h>

#include <cjson/cJSON.h>

#include "harness/internal.h"
#include "tcb/fsutil.h"
#include "tcb/json.h"

static int record_path(const char *checkpoint, char *out, tcb_error *err)
{
    return tcb_path_join(out, TCB_PATH_MAX, err, "%s.fit.json", checkpoint);
}

int tcb_fit_time_save(const char *checkpoint, double fit_s, tcb_error *err)
{
    char path[TCB_PATH_MAX];
    int rc = record_path(checkpoint, path, err);
    if (rc) return rc;
    cJSON *o = cJSON_CreateObject();
    if (!o || !cJSON_AddNumberToObject(o, "fit_s", fit_s)) {
        cJSON_Delete(o);
        return tcb_fail(err, TCB_ERR_NOMEM, "%s: out of memory", path);
    }
    rc = tcb_json_save(path, o, err);
    cJSON_Delete(o);
    return rc;
}

int tcb_fit_time_load(const char *checkpoint, double *fit_s, tcb_error *err)
{
    static const char *const keys[] = {"fit_s", NULL};
    char path[TCB_PATH_MAX];
    cJSON *o = NULL;
    int rc = record_path(checkpoint, path, err);
    if (!rc) rc = tcb_json_load(path, &o, err);
    if (!rc) rc = tcb_json_expect_keys(o, path, keys, err);
    if (!rc) rc = tcb_json_num(o, "fit_s", path, 1, 0, 0, INFINITY, fit_s, err);
    cJSON_Delete(o);
    return rc;
}
