/* Neu-PiG's time features (github vc-bonn/neu-pig,
 * src/network/time_encodings.py "fourier_features2"): for t̃ = frame
 * index / largest index ∈ [0, 1],
 *   out = [sin(2⁰πt̃), …, sin(2^(J−1)πt̃), cos(2⁰πt̃), …, cos(2^(J−1)πt̃)]
 * (all sines, then all cosines; J = 4 gives the method's 8 values). The
 * frame times are fixed, so nothing is trained and no gradient is needed. */
#ifndef TCB_NEURAL_FOURIER_TIME_H
#define TCB_NEURAL_FOURIER_TIME_H

#include <math.h>

static inline void tcb_fourier_time(double t, int J, float *out)
{
    for (int j = 0; j < J; j++) {
        double a = ldexp(M_PI * t, j);
        out[j] = (float)sin(a);
        out[J + j] = (float)cos(a);
    }
}

#endif
