/* Shared by the atlas benchmarks (atlas_forward.c, train_step.c): the
 * minimal FLOP count of the network. */
#ifndef TCB_BENCH_ATLAS_BENCH_H
#define TCB_BENCH_ATLAS_BENCH_H

#include "bench_util.h"

/* Multiply-adds of one forward (*fwd) and one backward (*bwd) of the atlas
 * network (latent C, P patches) for B shapes of N input points and M UV
 * samples, with nt = 2 tangents (φ_u, φ_v: MCA, DSR) or none (AtlasNet).
 * A GFLOP figure counts 2 FLOPs per multiply-add.
 *
 * The minimal count of the layers' products: per decoder the stacked
 * (1 + nt)·B·m-row GEMMs of layers 2–4 (m = M/P samples per patch), layer 1
 * split into its z part (B·C·H1, once per shape and patch) and its rank-2
 * uv part (B·m·2·H1, values only: the tangents of layer 1 are its weight
 * columns); the encoder's per-point convolutions (B·N·(3·64 + 64·128 +
 * 128·C)) and its two C×C layers. Backward: each layer's weight and input
 * gradients (2× its forward), except that conv1 has no input gradient,
 * conv3's input gradient reaches one point per (shape, channel) through the
 * max-pool, and layer 1's uv part is elementwise. Elementwise work
 * (activations, biases, losses, Adam) is not counted. */
static inline void bench_atlas_macs(int C, int P, int M, int B, int N, int nt, double *fwd,
                                    double *bwd)
{
    double pts = (double)B * N, c = C;
    double h1 = C + 2, h2 = (C + 2) / 2, h3 = (C + 2) / 4;
    double rows = (1.0 + nt) * B * (M / P), vals = (double)B * (M / P);
    double enc = pts * (3 * 64 + 64 * 128 + 128 * c) + B * 2 * c * c;
    double dec = B * c * h1 + vals * 2 * h1 + rows * (h1 * h2 + h2 * h3 + h3 * 3);
    *fwd = enc + P * dec;
    double enc_b = 2 * enc - pts * 3 * 64 - 2 * pts * 128 * c + 2.0 * B * c * 128;
    double dec_b = 2 * B * c * h1 + vals * 2 * h1 + 2 * rows * (h1 * h2 + h2 * h3 + h3 * 3);
    *bwd = enc_b + P * dec_b;
}

#endif
