/* The pcgrid methods' normalisation and keyframe (methods/pcgrid/prepare.h). */
#include "methods/pcgrid/prepare.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>

int tcb_pcgrid_frame_map_of(const float *const *points, const int *n, int T, tcb_pcgrid_frame_map *out,
                            tcb_error *err)
{
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    long long total = 0;
    for (int t = 0; t < T; t++)
        for (int i = 0; i < n[t]; i++, total++)
            for (int k = 0; k < 3; k++) {
                double x = points[t][3 * (size_t)i + k];
                if (!isfinite(x))
                    return tcb_fail(err, TCB_ERR_NUMERIC, "input clouds: frame %d, point %d is not finite", t, i);
                lo[k] = fmin(lo[k], x), hi[k] = fmax(hi[k], x);
            }
    if (!total) return tcb_fail(err, TCB_ERR_INPUT, "input clouds: no point");
    double half = 0.0;
    for (int k = 0; k < 3; k++) out->centre[k] = 0.5 * (hi[k] + lo[k]), half = fmax(half, 0.5 * (hi[k] - lo[k]));
    if (!(half > 0.0)) return tcb_fail(err, TCB_ERR_INPUT, "input clouds: every point is the same");
    out->scale = TCB_PCGRID_MARGIN / half;
    return TCB_OK;
}

void tcb_pcgrid_map_points(const tcb_pcgrid_frame_map *m, const float *pts, int n, float *out)
{
    for (size_t i = 0; i < 3 * (size_t)n; i++) out[i] = (float)((pts[i] - m->centre[i % 3]) * m->scale);
}

void tcb_pcgrid_unmap_points(const tcb_pcgrid_frame_map *m, float *pts, int n)
{
    for (size_t i = 0; i < 3 * (size_t)n; i++) pts[i] = (float)(pts[i] / m->scale + m->centre[i % 3]);
}

static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

/* Occupied cells of one frame: its points' cell keys, sorted, counted once. */
static int occupied(const float *pts, int n, int res, uint64_t *keys)
{
    for (int i = 0; i < n; i++) {
        uint64_t key = 0;
        for (int k = 0; k < 3; k++) {
            /* In float32 and truncated, as the reference's tensor .int(). */
            int64_t c = (int64_t)((pts[3 * (size_t)i + k] + 1.0f) / 2.0f * (float)res);
            key = key * (uint64_t)(2 * res + 1) + (uint64_t)(c + res); /* offset: c may leave [0, res] */
        }
        keys[i] = key;
    }
    qsort(keys, (size_t)n, sizeof *keys, cmp_u64);
    int count = n > 0;
    for (int i = 1; i < n; i++) count += keys[i] != keys[i - 1];
    return count;
}

int tcb_pcgrid_keyframe(const float *const *points, const int *n, int T, int res, int *key, tcb_error *err)
{
    int most = 0;
    for (int t = 0; t < T; t++) most = n[t] > most ? n[t] : most;
    uint64_t *keys = malloc((size_t)(most > 0 ? most : 1) * sizeof *keys);
    if (!keys) return tcb_fail(err, TCB_ERR_NOMEM, "keyframe: out of memory");
    double best = -1.0;
    int first = -((T + 1) / 2); /* ⌊−T/2⌋ */
    for (int t = 0; t < T; t++) {
        double k = first + t, score = occupied(points[t], n[t], res, keys) * exp(-0.001 * k * k);
        if (score > best) best = score, *key = t;
    }
    free(keys);
    return TCB_OK;
}
