/* A mannequin-like biped (height ≈ 1, feet on y ≈ 0, facing −z, arms
 * half raised at rest) doing jumping jacks: arms and legs abduct together
 * in the frontal plane, the knees give at each landing and the body hops.
 * The rest pose sits mid-range so no joint turns more than ~75° from it. */
#include <math.h>

#include "datasets/synth_internal.h"

enum {
    PELVIS,
    CHEST,
    NECK,
    HEAD,
    HIP,
    THIGH = HIP + 2,
    SHIN = THIGH + 2,
    FOOT = SHIN + 2,
    CLAVICLE = FOOT + 2,
    UPPER_ARM = CLAVICLE + 2,
    FOREARM = UPPER_ARM + 2,
    HAND = FOREARM + 2
};

#define TAU       6.283185307179586
#define ARM_LOW   (-0.6) /* arm rotation at the "closed" position, radians from rest */
#define LEG_SHARE 0.15   /* leg abduction as a fraction of the arm's swing */

void tcb_synth_humanoid_body(tcb_synth_body *b)
{
    tcb_synth_body_init(b, 0.025f, 0.045f);
    tcb_synth_body_add(b, -1, (float[]){0, 0.50f, 0}, (float[]){0, 0.60f, 0}, 0.08f, 0.08f);
    tcb_synth_body_add(b, PELVIS, (float[]){0, 0.60f, 0}, (float[]){0, 0.76f, 0}, 0.085f, 0.095f);
    tcb_synth_body_add(b, CHEST, (float[]){0, 0.78f, 0}, (float[]){0, 0.85f, 0}, 0.04f, 0.04f);
    tcb_synth_body_add(b, NECK, (float[]){0, 0.87f, -0.01f}, (float[]){0, 0.94f, -0.01f}, 0.07f,
                       0.065f);
    tcb_synth_body_add_pair(b, PELVIS, (float[]){0, 0.52f, 0}, (float[]){0.07f, 0.50f, 0}, 0.065f,
                            0.06f);
    tcb_synth_body_add_pair(b, HIP, (float[]){0.08f, 0.48f, 0}, (float[]){0.095f, 0.27f, 0}, 0.06f,
                            0.045f);
    tcb_synth_body_add_pair(b, THIGH, (float[]){0.095f, 0.27f, 0}, (float[]){0.10f, 0.06f, 0},
                            0.045f, 0.035f);
    tcb_synth_body_add_pair(b, SHIN, (float[]){0.10f, 0.05f, 0.01f},
                            (float[]){0.10f, 0.035f, -0.08f}, 0.035f, 0.03f);
    /* Arm: 60° from hanging, along (sin 60°, −cos 60°). */
    tcb_synth_body_add_pair(b, CHEST, (float[]){0, 0.76f, 0}, (float[]){0.13f, 0.77f, 0}, 0.055f,
                            0.05f);
    tcb_synth_body_add_pair(b, CLAVICLE, (float[]){0.14f, 0.77f, 0}, (float[]){0.2872f, 0.685f, 0},
                            0.042f, 0.035f);
    tcb_synth_body_add_pair(b, UPPER_ARM, (float[]){0.2872f, 0.685f, 0},
                            (float[]){0.4258f, 0.605f, 0}, 0.035f, 0.03f);
    tcb_synth_body_add_pair(b, FOREARM, (float[]){0.4258f, 0.605f, 0},
                            (float[]){0.4778f, 0.575f, 0}, 0.032f, 0.028f);
}

void tcb_synth_humanoid_pose(const tcb_synth_body *b, const tcb_synth_gait *g, double phase,
                             tcb_synth_pose *p)
{
    double c = TAU * phase, open = 0.5 - 0.5 * cos(c), air = fabs(sin(c));
    double arm = ARM_LOW + g->swing * open;
    double leg = LEG_SHARE * (ARM_LOW + g->swing * open);
    double knee = g->bend * (1.0 - air) * (1.0 - air); /* deepest at each landing */
    for (int side = 0; side < 2; side++) {
        tcb_synth_pose_rotate(p, b, UPPER_ARM + side, 0.0, 0.0, arm);
        tcb_synth_pose_rotate(p, b, FOREARM + side, 0.0, 0.0, 0.2 * arm);
        tcb_synth_pose_rotate(p, b, THIGH + side, 0.5 * knee, 0.0, leg);
        tcb_synth_pose_rotate(p, b, SHIN + side, -knee, 0.0, 0.0);
        tcb_synth_pose_rotate(p, b, FOOT + side, 0.5 * knee, 0.0, -leg);
    }
    tcb_synth_pose_rotate(p, b, HEAD, 0.05 * sin(2.0 * c), 0.0, 0.0);
    p->shift[1] = g->bounce * air;
}
