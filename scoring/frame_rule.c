/* The wrong-frame rule for point predictions (tcb/score.h,
 * docs/formats.md): points computed in the dataset's raw coordinates
 * instead of the split's normalised frame would be scored as a number
 * about the frames, not about the method, so they are refused.
 *
 * The mistake is tested directly. With fit the points' median distance to
 * the nearest vertex of the sequence (any frame: a transfer's points may
 * lie where the source frame was, as nearest's do), and fit_raw the same
 * for the points read as raw coordinates and normalised as the split
 * normalises frame j, N(p) = (p - norm_shift[j]) / norm_scale, the points
 * are refused when fit > TCB_FRAME_RAW_RATIO * fit_raw and fit >
 * TCB_FRAME_RAW_MIN * D (D: the diagonal of frame j's bounding box).
 * Whatever a method got wrong, its normalised points do not come to lie
 * on the shape once moved by the normalisation a second time; raw points
 * do, even where the normalisation is a small shift (the synthetic
 * sequences: half the height, scale 1.05). Measured (docs/formats.md):
 * oracle, nearest and nricp (random) on the synthetic sequences, the cat
 * and the crane have ratios fit / fit_raw of at most 0.21 and fit at most
 * 0.003 D; raw points have ratios of 1e7 and more, and still 3.3 and more
 * with noise of 0.05 D added, at fit of 0.04 D and more. The median, not
 * the mean: a method that went wrong on some vertices keeps most of them
 * on the shape. With normalization "none" N is the identity: nothing is
 * refused as raw.
 *
 * Points with fit beyond TCB_FRAME_FAR (100) box diagonals are refused
 * in any frame: a median point that far from every vertex of every frame
 * is no point of the shape (vertex ids written as x, a unit a thousand
 * times off), which the raw test cannot tell when the normalisation is
 * near the identity; a diverged method's points, even blown up tenfold,
 * stay well within it. */
#include <math.h>
#include <stdlib.h>

#include "tcb/geometry.h"
#include "tcb/nn.h"
#include "tcb/predictions.h"

static int by_value(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

/* The median distance from the n points q to their nearest point of nn. */
static int median_fit(const tcb_nn *nn, const float *q, int n, float *d2, int32_t *idx, double *out, tcb_error *err)
{
    int rc = tcb_nn_query1(nn, q, n, idx, d2, err);
    if (rc) return rc;
    qsort(d2, (size_t)n, sizeof *d2, by_value);
    *out = sqrt((double)d2[n / 2]);
    return TCB_OK;
}

/* The points as raw coordinates normalised, (p - shift) / scale; 0 when
 * one lands beyond the search's range (they fit nothing there). */
static int normalised(const float *p, int n, const double shift[3], double scale, float *out)
{
    for (size_t k = 0; k < (size_t)n * 3; k++) {
        double x = ((double)p[k] - shift[k % 3]) / scale;
        if (!(fabs(x) <= TCB_NN_COORD_MAX)) return 0;
        out[k] = (float)x;
    }
    return 1;
}

int tcb_frame_fit_measure(const tcb_nn *shape, const float *verts_j, int nv, const float *points, int n,
                          const double shift[3], double scale, tcb_frame_fit *f, tcb_error *err)
{
    double box[6];
    tcb_bbox(verts_j, (size_t)nv, box);
    f->diag = tcb_bbox_diag(box);
    float *q = malloc((size_t)n * 3 * sizeof *q), *dist2 = malloc((size_t)n * sizeof *dist2);
    int32_t *idx = malloc((size_t)n * sizeof *idx);
    int rc = !q || !dist2 || !idx ? tcb_fail(err, TCB_ERR_NOMEM, "out of memory for %d points", n) : TCB_OK;
    if (!rc) rc = median_fit(shape, points, n, dist2, idx, &f->fit, err);
    f->fit_raw = INFINITY;
    if (!rc && normalised(points, n, shift, scale, q)) rc = median_fit(shape, q, n, dist2, idx, &f->fit_raw, err);
    free(q);
    free(dist2);
    free(idx);
    return rc;
}

int tcb_score_check_frame(const tcb_nn *shape, const float *verts_j, int nv, const float *points, int n,
                          const double shift[3], double scale, tcb_error *err)
{
    tcb_frame_fit f;
    int rc = tcb_frame_fit_measure(shape, verts_j, nv, points, n, shift, scale, &f, err);
    if (rc) return rc;
    if (f.fit > TCB_FRAME_FAR * f.diag)
        return tcb_fail(err, TCB_ERR_INPUT,
                        "the points lie a median %.3g box diagonals from the sequence's vertices (more than %g): "
                        "no points of the shape (vertex ids or another unit written as coordinates?)",
                        f.fit / f.diag, TCB_FRAME_FAR);
    if (f.fit > TCB_FRAME_RAW_RATIO * f.fit_raw && f.fit > TCB_FRAME_RAW_MIN * f.diag)
        return tcb_fail(err, TCB_ERR_INPUT,
                        "the points lie a median %.3g box diagonals from the sequence's vertices, %.3g once "
                        "normalised as the split's frames are (more than %g times closer): the dataset's raw coordinates",
                        f.fit / f.diag, f.fit_raw / f.diag, TCB_FRAME_RAW_RATIO);
    return TCB_OK;
}
