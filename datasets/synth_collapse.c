/* The non-articulated half of a collapse (tcb_synth_collapse_*): the
 * flesh deflates towards the skeleton and the body sags onto the ground,
 * spreading and folding over itself there. With the quadruped's buckling
 * limbs (synth_quadruped.c) this makes the stress test's kind of motion
 * (Sumner & Popović's horse and camel "collapse", the paper's Table 10):
 * strongly non-isometric, one topology throughout. */
#include <math.h>
#include <stddef.h>

#include "datasets/synth_internal.h"

#define DEFLATE   0.35  /* radial shrink of the flesh at full collapse */
#define SQUASH    0.35  /* vertical shrink at full collapse */
#define SPREAD    0.30  /* horizontal widening at the ground at full collapse */
#define SPREAD_Y  0.10  /* height over which the widening fades (e-folding) */
#define FLOOR_EPS 0.012 /* thickness of the soft floor layer flesh piles into */

/* Closest point to p on the bone's segment a–b. */
static void closest_on_bone(const tcb_synth_bone *bone, const float p[3], double q[3])
{
    double u[3], d[3], uu = 0.0, ud = 0.0;
    for (int k = 0; k < 3; k++) {
        u[k] = (double)bone->b[k] - bone->a[k];
        d[k] = (double)p[k] - bone->a[k];
        uu += u[k] * u[k];
        ud += u[k] * d[k];
    }
    double t = uu > 0.0 ? fmin(1.0, fmax(0.0, ud / uu)) : 0.0;
    for (int k = 0; k < 3; k++) q[k] = bone->a[k] + t * u[k];
}

void tcb_synth_collapse_deflate(const tcb_synth_body *b, const tcb_synth_skin *s,
                                const float *rest, double amount, float *out)
{
    /* Towards the skin-weighted blend of the bones' axes, so the flesh
     * shrinks smoothly across joints instead of tearing between bones. */
    const double keep = 1.0 - DEFLATE * amount;
    for (int v = 0; v < s->n_verts; v++) {
        const float *p = rest + 3 * (size_t)v;
        double axis[3] = {0.0, 0.0, 0.0};
        for (int j = 0; j < TCB_SYNTH_SKIN_K; j++) {
            double q[3], w = s->weight[(size_t)v * TCB_SYNTH_SKIN_K + j];
            closest_on_bone(&b->bones[s->bone[(size_t)v * TCB_SYNTH_SKIN_K + j]], p, q);
            for (int k = 0; k < 3; k++) axis[k] += w * q[k];
        }
        for (int k = 0; k < 3; k++) out[3 * (size_t)v + k] = (float)(axis[k] + keep * (p[k] - axis[k]));
    }
}

/* A smooth floor at y = 0: what sinks below it piles into a layer a few
 * FLOOR_EPS thick (softplus), so surfaces fold onto each other there
 * without any vertex being projected onto another exactly. */
static double soft_floor(double y)
{
    double x = y / FLOOR_EPS;
    return FLOOR_EPS * (x > 30.0 ? x : log1p(exp(x)));
}

void tcb_synth_collapse_sag(float *verts, int nv, const double centre[2], double amount)
{
    for (int v = 0; v < nv; v++) {
        float *p = verts + 3 * (size_t)v;
        double y = p[1] * (1.0 - SQUASH * amount);
        double widen = 1.0 + SPREAD * amount * exp(-fmax(y, 0.0) / SPREAD_Y);
        p[0] = (float)(centre[0] + widen * (p[0] - centre[0]));
        p[2] = (float)(centre[1] + widen * (p[2] - centre[1]));
        p[1] = (float)soft_floor(y);
    }
}
