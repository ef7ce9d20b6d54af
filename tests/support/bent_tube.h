/* A closed, body-like test mesh shared by test_geodesic and
 * bench_geodesic: an elongated ellipsoid whose axis is bent into an arc,
 * a U at π, where the straight line between the arms is short and the path
 * along the surface long (the hard case for a Euclidean bound).
 * Header-only: each program is one translation unit. */
#ifndef TCB_TEST_BENT_TUBE_H
#define TCB_TEST_BENT_TUBE_H

#include <math.h>
#include <stdint.h>

#include "tcb/rng.h"

/* Vertex counts of a tube of `rings` × `segs` (plus two poles). */
static inline int bent_tube_verts(int rings, int segs) { return 2 + rings * segs; }
static inline int bent_tube_faces(int rings, int segs) { return 2 * segs * rings; }

/* verts [bent_tube_verts][3], faces [bent_tube_faces][3]: radius 1 (each
 * vertex's scaled by 1 + bump·(u − 1/2), u uniform from `seed`), length
 * len along the axis, the axis an arc of angle `bend` radians (> 0). */
static inline void bent_tube(int rings, int segs, double len, double bend, double bump, uint64_t seed,
                             float *verts, int32_t *faces)
{
    tcb_rng rng;
    tcb_rng_seed(&rng, seed);
    int nv = bent_tube_verts(rings, segs);
    for (int k = 0; k < nv; k++) {
        double alpha = k == 0 ? 0 : k == 1 ? M_PI : M_PI * ((k - 2) / segs + 1) / (rings + 1);
        double beta = k < 2 ? 0 : 2 * M_PI * ((k - 2) % segs) / segs;
        double r = 1.0 + bump * (tcb_rng_uniform(&rng) - 0.5);
        double x = r * sin(alpha) * cos(beta), y = 0.5 * len * cos(alpha), z = r * sin(alpha) * sin(beta);
        double rho = len / bend, phi = y / rho;
        verts[3 * k] = (float)(rho * (1 - cos(phi)) + x * cos(phi));
        verts[3 * k + 1] = (float)(rho * sin(phi) - x * sin(phi));
        verts[3 * k + 2] = (float)z;
    }
    int32_t *t = faces;
#define RING(a, b) (2 + (a) * segs + ((b) % segs))
    for (int b = 0; b < segs; b++) {
        *t++ = 0, *t++ = RING(0, b + 1), *t++ = RING(0, b);
        *t++ = 1, *t++ = RING(rings - 1, b), *t++ = RING(rings - 1, b + 1);
    }
    for (int a = 0; a + 1 < rings; a++)
        for (int b = 0; b < segs; b++) {
            *t++ = RING(a, b), *t++ = RING(a, b + 1), *t++ = RING(a + 1, b);
            *t++ = RING(a + 1, b), *t++ = RING(a, b + 1), *t++ = RING(a + 1, b + 1);
        }
#undef RING
}

#endif
