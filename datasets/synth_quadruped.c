/* A dog-like quadruped (body length ≈ 1.1, feet on y ≈ 0, facing −z) and
 * its gaits: each leg swings fore and aft about its hip or shoulder and
 * folds its lower leg while travelling forward; the gait's `lead` offsets
 * set the footfall order (walk: lateral sequence; trot: diagonal pairs). */
#include <math.h>

#include "datasets/synth_internal.h"

enum {
    BACK,
    CHEST,
    NECK,
    HEAD,
    TAIL,
    LF_UPPER,
    LF_LOWER = LF_UPPER + 2,
    LF_PAW = LF_LOWER + 2,
    LH_UPPER = LF_PAW + 2,
    LH_LOWER = LH_UPPER + 2,
    LH_PAW = LH_LOWER + 2
};

#define LEG_X 0.10f /* hip and shoulder offset from the sagittal plane */
#define TAU   6.283185307179586

void tcb_synth_quadruped_body(tcb_synth_body *b)
{
    tcb_synth_body_init(b, 0.03f, 0.055f);
    tcb_synth_body_add(b, -1, (float[]){0, 0.55f, 0.22f}, (float[]){0, 0.56f, 0}, 0.125f, 0.135f);
    tcb_synth_body_add(b, BACK, (float[]){0, 0.56f, 0}, (float[]){0, 0.57f, -0.22f}, 0.135f, 0.14f);
    tcb_synth_body_add(b, CHEST, (float[]){0, 0.60f, -0.22f}, (float[]){0, 0.72f, -0.34f}, 0.07f,
                       0.06f);
    tcb_synth_body_add(b, NECK, (float[]){0, 0.72f, -0.34f}, (float[]){0, 0.69f, -0.50f}, 0.085f,
                       0.05f);
    tcb_synth_body_add(b, BACK, (float[]){0, 0.60f, 0.30f}, (float[]){0, 0.66f, 0.50f}, 0.04f,
                       0.03f);
    /* Front leg: upper arm, forearm, paw pointing forward. */
    tcb_synth_body_add_pair(b, CHEST, (float[]){LEG_X, 0.50f, -0.24f},
                            (float[]){LEG_X, 0.29f, -0.23f}, 0.055f, 0.045f);
    tcb_synth_body_add_pair(b, LF_UPPER, (float[]){LEG_X, 0.29f, -0.23f},
                            (float[]){LEG_X, 0.06f, -0.24f}, 0.045f, 0.04f);
    tcb_synth_body_add_pair(b, LF_LOWER, (float[]){LEG_X, 0.06f, -0.24f},
                            (float[]){LEG_X, 0.045f, -0.29f}, 0.04f, 0.035f);
    /* Hind leg: thigh angled forward, shin angled back, paw. */
    tcb_synth_body_add_pair(b, BACK, (float[]){LEG_X, 0.50f, 0.22f}, (float[]){LEG_X, 0.30f, 0.16f},
                            0.065f, 0.05f);
    tcb_synth_body_add_pair(b, LH_UPPER, (float[]){LEG_X, 0.30f, 0.16f},
                            (float[]){LEG_X, 0.06f, 0.22f}, 0.045f, 0.04f);
    tcb_synth_body_add_pair(b, LH_LOWER, (float[]){LEG_X, 0.06f, 0.22f},
                            (float[]){LEG_X, 0.045f, 0.17f}, 0.04f, 0.035f);
}

/* One leg at cycle angle c: the swing is forward (+ about x) while sin c
 * rises, and the lower leg folds back only during that forward swing. */
static void leg(const tcb_synth_body *b, const tcb_synth_gait *g, int upper, double c,
                tcb_synth_pose *p)
{
    double fold = fmax(0.0, cos(c));
    tcb_synth_pose_rotate(p, b, upper, g->swing * sin(c), 0.0, 0.0);
    tcb_synth_pose_rotate(p, b, upper + 2, -g->bend * fold * fold, 0.0, 0.0);
    tcb_synth_pose_rotate(p, b, upper + 4, 0.5 * g->bend * fold * fold, 0.0, 0.0);
}

void tcb_synth_quadruped_pose(const tcb_synth_body *b, const tcb_synth_gait *g, double phase,
                              tcb_synth_pose *p)
{
    const double c = TAU * phase;
    /* lead[] is LF, RF, LH, RH; the right (−x) bone is the left one + 1. */
    leg(b, g, LF_UPPER, c + TAU * g->lead[0], p);
    leg(b, g, LF_UPPER + 1, c + TAU * g->lead[1], p);
    leg(b, g, LH_UPPER, c + TAU * g->lead[2], p);
    leg(b, g, LH_UPPER + 1, c + TAU * g->lead[3], p);
    tcb_synth_pose_rotate(p, b, CHEST, 0.0, 0.06 * sin(c), 0.0);
    tcb_synth_pose_rotate(p, b, HEAD, 0.08 * sin(2.0 * c), 0.0, 0.0);
    tcb_synth_pose_rotate(p, b, TAIL, 0.1 * sin(c + 1.0), 0.3 * sin(c), 0.0);
    p->shift[1] = g->bounce * sin(2.0 * c);
}

/* The quadruped giving way (progress s from 0, standing, to 1, down): the
 * legs splay outwards (gait `swing`, radians) and fold (`bend`), neck,
 * head and tail droop, and the body drops by `bounce` (body-length units)
 * to lie on the ground, so the feet sink through the floor and pile there
 * (tcb_synth_collapse_sag). */
void tcb_synth_quadruped_collapse_pose(const tcb_synth_body *b, const tcb_synth_gait *g, double s,
                                       tcb_synth_pose *p)
{
    static const int uppers[] = {LF_UPPER, LF_UPPER + 1, LH_UPPER, LH_UPPER + 1};
    for (int k = 0; k < 4; k++) {
        /* Hind legs fold the other way (their knee points forward). */
        double fold = (k < 2 ? -1.0 : 1.0) * g->bend * s;
        tcb_synth_pose_rotate(p, b, uppers[k], 0.0, 0.0, g->swing * s);
        tcb_synth_pose_rotate(p, b, uppers[k] + 2, fold, 0.0, 0.0);
        tcb_synth_pose_rotate(p, b, uppers[k] + 4, -0.5 * fold, 0.0, 0.0);
    }
    tcb_synth_pose_rotate(p, b, NECK, -0.9 * s, 0.0, 0.0);
    tcb_synth_pose_rotate(p, b, HEAD, -0.4 * s, 0.0, 0.0);
    tcb_synth_pose_rotate(p, b, TAIL, 0.6 * s, 0.0, 0.0);
    p->shift[1] = -g->bounce * s;
}
