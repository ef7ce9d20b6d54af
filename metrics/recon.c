/* The reconstruction metrics of the 2024-2026 papers: Chamfer-L2, normal
 * consistency and F-score at 0.5 % and 1 % (tcb/metrics.h; DynoSurf's
 * evaluation/utils.py defines them, after Occupancy Networks' eval.py).
 * tcbench's own code: the nearest neighbours come from tcb/nn.h, everything
 * after them is summed in double. */
#include <math.h>
#include <stdlib.h>

#include "tcb/geometry.h"
#include "tcb/metrics.h"
#include "tcb/nn.h"

const char *const tcb_recon_names[TCB_N_RECON] = {"cdl2", "nc", "fscore05", "fscore1"};
const char *const tcb_recon_frame_names[] = {"sequence", "frame_box", NULL};

void tcb_frame_box_map(const float *gt, int n, double centre[3], double *scale)
{
    double box[6], extent = 0.0;
    tcb_bbox(gt, (size_t)n, box);
    for (int d = 0; d < 3; d++) centre[d] = 0.5 * (box[d] + box[3 + d]), extent = fmax(extent, box[3 + d] - box[d]);
    *scale = extent > 0.0 ? 1.0 / extent : 0.0;
}

void tcb_frame_box_apply(const double centre[3], double scale, float *pts, int n)
{
    for (size_t i = 0; i < 3 * (size_t)n; i++) pts[i] = (float)((pts[i] - centre[i % 3]) * scale);
}

int tcb_recon_sample(const float *verts, const int32_t *faces, int nf, int n, tcb_rng *rng,
                     float *pts, float *normals, tcb_error *err)
{
    int32_t *face_of = malloc((size_t)(n > 0 ? n : 1) * sizeof *face_of);
    if (!face_of) return tcb_fail(err, TCB_ERR_NOMEM, "surface samples: cannot allocate %d", n);
    int rc = tcb_sample_surface_faces(verts, faces, nf, n, rng, pts, face_of, err);
    for (int s = 0; !rc && s < n; s++) tcb_face_normal(verts, faces + 3 * (size_t)face_of[s], normals + 3 * (size_t)s);
    free(face_of);
    return rc;
}

/* One direction: for each query q, the distance to its nearest target and
 * |n_q · n_target|, accumulated as the mean squared distance, the mean
 * |cos| and the fraction within each F-score threshold. */
typedef struct one_way {
    double d2, cos, within05, within1;
} one_way;

static int nearest_side(const float *q, const float *q_n, int nq, const float *t, const float *t_n, int nt,
                        one_way *out, tcb_error *err)
{
    tcb_nn *nn = NULL;
    int32_t *idx = malloc((size_t)nq * sizeof *idx);
    int rc = idx ? tcb_nn_build(t, nt, &nn, err) : tcb_fail(err, TCB_ERR_NOMEM, "surface metrics: out of memory");
    if (!rc) rc = tcb_nn_query1(nn, q, nq, idx, NULL, err);
    *out = (one_way){0, 0, 0, 0};
    for (int k = 0; !rc && k < nq; k++) {
        const float *a = q + 3 * (size_t)k, *b = t + 3 * (size_t)idx[k];
        const float *na = q_n + 3 * (size_t)k, *nb = t_n + 3 * (size_t)idx[k];
        double dx = (double)a[0] - b[0], dy = (double)a[1] - b[1], dz = (double)a[2] - b[2];
        double d2 = dx * dx + dy * dy + dz * dz, d = sqrt(d2);
        out->d2 += d2;
        out->cos += fabs((double)na[0] * nb[0] + (double)na[1] * nb[1] + (double)na[2] * nb[2]);
        out->within05 += d <= TCB_FSCORE_T05;
        out->within1 += d <= TCB_FSCORE_T1;
    }
    if (!rc) {
        out->d2 /= nq, out->cos /= nq, out->within05 /= nq, out->within1 /= nq;
    }
    tcb_nn_free(nn);
    free(idx);
    return rc;
}

static double fscore(double precision, double recall)
{
    return precision + recall > 0 ? 2 * precision * recall / (precision + recall) : 0;
}

int tcb_recon_metrics(const float *pred, const float *pred_n, int np, const float *gt,
                      const float *gt_n, int ng, double out[TCB_N_RECON], tcb_error *err)
{
    if (np < 1 || ng < 1)
        return tcb_fail(err, TCB_ERR_INPUT, "surface metrics: %d predicted and %d GT samples (need one each)", np,
                        ng);
    one_way acc, comp;
    int rc = nearest_side(pred, pred_n, np, gt, gt_n, ng, &acc, err);
    if (!rc) rc = nearest_side(gt, gt_n, ng, pred, pred_n, np, &comp, err);
    if (rc) return rc;
    out[TCB_RECON_CDL2] = 0.5 * (acc.d2 + comp.d2);
    out[TCB_RECON_NC] = 0.5 * (acc.cos + comp.cos);
    out[TCB_RECON_FSCORE05] = fscore(acc.within05, comp.within05);
    out[TCB_RECON_FSCORE1] = fscore(acc.within1, comp.within1);
    return TCB_OK;
}
