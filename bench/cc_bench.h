/* Shared by the cc benchmarks (train_step.c): the minimal FLOP count of
 * one CC training iteration. */
#ifndef TCB_BENCH_CC_BENCH_H
#define TCB_BENCH_CC_BENCH_H

#include "bench_util.h"
#include "methods/cycle/net.h"

/* Multiply-adds of the forward (*fwd) and backward (*bwd) of one CC
 * iteration after the warm-up: 3 clouds of B shapes × N points, each
 * encoded once by each encoder (6 encoder forwards), and 6 decoder calls
 * (the ordered pairs). A GFLOP figure counts 2 FLOPs per multiply-add.
 *
 * Encoder: B·N·(3·64 + 64·128 + 128·C) per-point products and B·C·Z for
 * the projection. Decoder: the predictor B·(2Z·Z + Z·Z/2 + Z/2·K) and per
 * meta layer B·N·(din² + din·dout) (the predicted product and the conv).
 * Backward: each product's weight and input gradients (2× its forward),
 * except conv1 (no input gradient); conv3's input gradient is dense (the
 * batch norm between conv3 and the max-pool spreads it over every point).
 * Elementwise work (batch norm, activations, losses, Adam) and the
 * losses' nearest-neighbour searches are not counted. */
static inline void bench_cc_macs(const tcb_cc_dims *d, int B, int N, double *fwd, double *bwd)
{
    double pts = (double)B * N, C = d->C, Z = d->Z, H = d->H;
    double K = 12 + d->L * (H * H + H);
    double enc = pts * (3 * 64 + 64 * 128 + 128 * C) + B * C * Z;
    double meta = (9 + 3 * H) + (d->L - 1) * 2 * H * H + (H * H + 3 * H);
    double dec = B * (2 * Z * Z + Z * Z / 2 + Z / 2 * K) + pts * meta;
    *fwd = 6 * (enc + dec);
    *bwd = 6 * (2 * enc - pts * 3 * 64 + 2 * dec);
}

#endif
