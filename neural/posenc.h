/* NeRF's positional encoding of points (Mildenhall et al. 2020; the
 * "Embedder" DynoSurf's networks use, code/model/dmtet_network.py, with
 * log-sampled frequencies and the input kept):
 *   out = [x, sin(f_0 x), cos(f_0 x), …, sin(f_{F−1} x), cos(f_{F−1} x)],
 *   f_k = 2^k, each block d wide, so [n][d·(1 + 2F)] for x [n][d].
 * No π: the reference multiplies by the frequency alone. The backward
 * serves inputs that are learned (DynoSurf's control points):
 *   ∂L/∂x = dout_x + Σ_k f_k (cos(f_k x) dout_sin_k − sin(f_k x) dout_cos_k). */
#ifndef TCB_NEURAL_POSENC_H
#define TCB_NEURAL_POSENC_H

#include <math.h>

static inline int tcb_posenc_width(int d, int n_freqs) { return d * (1 + 2 * n_freqs); }

static inline void tcb_posenc_forward(const float *x, int n, int d, int n_freqs, float *out)
{
    int w = tcb_posenc_width(d, n_freqs);
    for (long i = 0; i < n; i++) {
        const float *xi = x + i * d;
        float *o = out + i * w;
        for (int k = 0; k < d; k++) o[k] = xi[k];
        for (int f = 0; f < n_freqs; f++)
            for (int k = 0; k < d; k++) {
                /* In float, as the reference's float32 tensors. */
                float a = xi[k] * (float)(1 << f);
                o[d * (1 + 2 * f) + k] = sinf(a);
                o[d * (2 + 2 * f) + k] = cosf(a);
            }
    }
}

/* dx [n][d] = ∂L/∂x for dout [n][d·(1 + 2F)] = ∂L/∂out (overwrites). */
static inline void tcb_posenc_backward(const float *x, const float *dout, int n, int d, int n_freqs, float *dx)
{
    int w = tcb_posenc_width(d, n_freqs);
    for (long i = 0; i < n; i++) {
        const float *xi = x + i * d, *g = dout + i * w;
        for (int k = 0; k < d; k++) {
            double s = g[k];
            for (int f = 0; f < n_freqs; f++) {
                float scale = (float)(1 << f), a = xi[k] * scale;
                s += scale * ((double)cosf(a) * g[d * (1 + 2 * f) + k] - (double)sinf(a) * g[d * (2 + 2 * f) + k]);
            }
            dx[i * d + k] = (float)s;
        }
    }
}

#endif
