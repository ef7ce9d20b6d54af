#include "views/colormap.h"

#include <float.h>
#include <stddef.h>

void tcb_color_by_position(const float *ref, int n, uint8_t *rgb)
{
    float lo[3] = {FLT_MAX, FLT_MAX, FLT_MAX}, hi[3] = {-FLT_MAX, -FLT_MAX, -FLT_MAX};
    for (int k = 0; k < n; k++)
        for (int a = 0; a < 3; a++) {
            float v = ref[3 * (size_t)k + a];
            lo[a] = v < lo[a] ? v : lo[a];
            hi[a] = v > hi[a] ? v : hi[a];
        }
    for (int k = 0; k < n; k++)
        for (int a = 0; a < 3; a++) {
            float ext = hi[a] - lo[a];
            float t = ext > 0 ? (ref[3 * (size_t)k + a] - lo[a]) / ext : 0.5f;
            /* 40..255: no vertex is black, which viewers draw as unlit. */
            rgb[3 * (size_t)k + a] = (uint8_t)(40.5f + 215.0f * t);
        }
}

void tcb_color_by_error(double err, double err_max, uint8_t *rgb)
{
    /* viridis at 0, 1/4, 1/2, 3/4, 1 (matplotlib's table), linearly between. */
    static const uint8_t stops[5][3] = {
        {68, 1, 84}, {59, 82, 139}, {33, 145, 140}, {94, 201, 98}, {253, 231, 37}};
    double t = err_max > 0 ? err / err_max : 1;
    t = t < 0 ? 0 : t > 1 ? 1 : t;
    int s = t >= 1 ? 3 : (int)(t * 4);
    double f = t * 4 - s;
    for (int a = 0; a < 3; a++)
        rgb[a] = (uint8_t)(stops[s][a] + f * (stops[s + 1][a] - stops[s][a]) + 0.5);
}
