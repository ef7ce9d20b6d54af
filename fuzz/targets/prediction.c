/* The prediction files of `tcbench score` (scoring/prediction_files.c): a .npy
 * of vertex ids or moved points, read for frames of 4 and of 5 vertices
 * (the seeds' sizes); what is accepted is in range and finite. */
#include <math.h>
#include <stdlib.h>

#include "fuzz/fuzz_util.h"
#include "tcb/score.h"

static void read_prediction(const char *path, int nv)
{
    int32_t pred[5];
    float moved[3 * 5];
    int is_points = -1;
    tcb_error err = {0};
    int rc = tcb_score_read_prediction(path, nv, pred, moved, &is_points, &err);
    fuzz_check_answer(rc, &err, path);
    if (rc) return;
    if (is_points)
        for (int k = 0; k < 3 * nv; k++) fuzz_require(isfinite(moved[k]), "finite points");
    else
        for (int k = 0; k < nv; k++) fuzz_require(pred[k] >= 0 && pred[k] < nv, "ids of the frame's vertices");
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *path = fuzz_file("pred.npy", data, size);
    read_prediction(path, 4);
    read_prediction(path, 5);
    float *pts;
    int n;
    tcb_error e2 = {0};
    int rc = tcb_score_read_points(path, &pts, &n, &e2);
    fuzz_check_answer(rc, &e2, path);
    if (!rc) free(pts);
    return 0;
}
