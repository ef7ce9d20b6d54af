/* Trilinear sampling of a feature lattice and its adjoint (neural/lattice.h). */
#include "neural/lattice.h"

#include <math.h>

/* Cell index (≤ r − 2) and offset in [0, 1] of one coordinate; r ≥ 2. */
static int cell(int r, float x, float *t)
{
    float u = (x + 1.0f) * 0.5f * (float)(r - 1);
    u = fminf(fmaxf(u, 0.0f), (float)(r - 1)); /* border padding */
    int i = (int)u;
    if (i > r - 2) i = r - 2;
    *t = u - (float)i;
    return i;
}

void tcb_lattice_corners(int r, const float p[3], int32_t node[8], float w[8])
{
    if (r == 1) {
        for (int c = 0; c < 8; c++) node[c] = 0, w[c] = c ? 0.0f : 1.0f;
        return;
    }
    float tx, ty, tz;
    int ix = cell(r, p[0], &tx), iy = cell(r, p[1], &ty), iz = cell(r, p[2], &tz);
    for (int c = 0; c < 8; c++) {
        int dx = c & 1, dy = (c >> 1) & 1, dz = c >> 2;
        node[c] = ((iz + dz) * r + (iy + dy)) * r + (ix + dx);
        w[c] = (dx ? tx : 1.0f - tx) * (dy ? ty : 1.0f - ty) * (dz ? tz : 1.0f - tz);
    }
}

void tcb_lattice_forward(float *out, const float *values, int r, int F, const float *pts, int n,
                         float scale)
{
#pragma omp parallel for schedule(static)
    for (int p = 0; p < n; p++) {
        int32_t node[8];
        float w[8];
        tcb_lattice_corners(r, pts + 3 * (int64_t)p, node, w);
        float *o = out + (int64_t)p * F;
        for (int c = 0; c < 8; c++) {
            const float *v = values + (int64_t)node[c] * F;
            float s = scale * w[c];
            for (int f = 0; f < F; f++) o[f] += s * v[f];
        }
    }
}

void tcb_lattice_backward(float *dvalues, const float *dout, int r, int F, const float *pts, int n,
                          float scale)
{
    for (int p = 0; p < n; p++) {
        int32_t node[8];
        float w[8];
        tcb_lattice_corners(r, pts + 3 * (int64_t)p, node, w);
        const float *d = dout + (int64_t)p * F;
        for (int c = 0; c < 8; c++) {
            float *g = dvalues + (int64_t)node[c] * F;
            float s = scale * w[c];
            for (int f = 0; f < F; f++) g[f] += s * d[f];
        }
    }
}

/* ∂t/∂x of one coordinate: (r − 1)/2 inside the cube, 0 where the border
 * clamp holds it (PyTorch's rule, the bounds included). */
static float offset_slope(int r, float x)
{
    float u = (x + 1.0f) * 0.5f * (float)(r - 1);
    return u > 0.0f && u < (float)(r - 1) ? 0.5f * (float)(r - 1) : 0.0f;
}

void tcb_lattice_backward_points(float *dpts, const float *dout, const float *values, int r, int F,
                                 const float *pts, int n, float scale)
{
    if (r == 1) return; /* a constant */
#pragma omp parallel for schedule(static)
    for (int p = 0; p < n; p++) {
        const float *q = pts + 3 * (int64_t)p, *d = dout + (int64_t)p * F;
        float t[3];
        int i[3];
        for (int a = 0; a < 3; a++) i[a] = cell(r, q[a], &t[a]);
        float g[3] = {0.0f, 0.0f, 0.0f};
        for (int c = 0; c < 8; c++) {
            int bit[3] = {c & 1, (c >> 1) & 1, c >> 2};
            const float *v = values + ((int64_t)((i[2] + bit[2]) * r + (i[1] + bit[1])) * r + (i[0] + bit[0])) * F;
            float dot = 0.0f;
            for (int f = 0; f < F; f++) dot += v[f] * d[f];
            float w1[3]; /* each axis's factor of the weight */
            for (int a = 0; a < 3; a++) w1[a] = bit[a] ? t[a] : 1.0f - t[a];
            for (int a = 0; a < 3; a++) { /* ∂w/∂t_a: that factor's ±1 times the other two */
                float dw = bit[a] ? 1.0f : -1.0f;
                for (int b = 0; b < 3; b++)
                    if (b != a) dw *= w1[b];
                g[a] += dw * dot;
            }
        }
        for (int a = 0; a < 3; a++) dpts[3 * (int64_t)p + a] += scale * offset_slope(r, q[a]) * g[a];
    }
}
