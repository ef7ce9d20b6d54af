/* CC (Groueix et al., SGP'19, "Unsupervised cycle-consistent deformation for
 * shape matching"): the per-frame normalization into the network's range and
 * the training-time data augmentation.
 *
 * Reference: ThibaultGROUEIX/CycleConsistentDeformation,
 *   auxiliary/normalize_points.py (BoundingBox, center_bounding_box,
 *     get_3D_rot_matrix, uniform_rotation_axis_matrix, uniform_rotation_axis,
 *     anisotropic_scaling, add_random_translation),
 *   auxiliary/dataset_shapenet.py ShapeNetSeg.getAnItem (the order of the
 *     augmentations; training/trainer.py build_dataset_train sets
 *     data_augmentation_Z_rotation=True, range 40, anisotropic_scaling=1,
 *     normalization "BoundingBox", random_translation=True),
 *   training/triplet_point_cloud.py compute_loss_selfReconstruction (P4).
 *
 * Point clouds are [n][3] floats, row-major, one point per row (the CC code
 * multiplies row vectors from the right: points · M). */
#ifndef TCB_CC_AUGMENT_H
#define TCB_CC_AUGMENT_H

#include "tcb/error.h"
#include "tcb/rng.h"
#include "tcb/sequence.h"

/* ---- per-frame normalization ("CC box") --------------------------------
 *
 * CC's decoder outputs absolute positions 2·tanh(·) ∈ (−2, 2), and the CC
 * code brings every shape to [−1, 1] at load (normalize_points.BoundingBox:
 * subtract the centre of the axis-aligned bounding box, divide by the
 * largest half-extent). tcbench normalizes per dataset instead (ANIM: unit
 * cube of frame 0; DFAUST: raw metres; AMA: centred per frame, unscaled), so
 * the method maps every frame into its own CC box before the network and
 * maps predictions back with the inverse:
 *     apply:  x ↦ (x − center) / scale
 *     invert: y ↦ y · scale + center
 * After `apply` every point of the frame's pool lies in [−1, 1]³ and the
 * largest half-extent is exactly 1 (up to float rounding); augmentation
 * (below) keeps clouds within [−1.03, 1.03]³, so the output range (−2, 2)
 * leaves margin. The box is computed from ALL pool points of the frame (the
 * method sees point clouds, never the mesh). */
typedef struct tcb_cc_frame_box {
    float center[3]; /* bounding-box centre (min + max) / 2, per axis */
    float scale;     /* largest half-extent max_d (max_d − min_d) / 2, > 0 */
} tcb_cc_frame_box;

/* The box of n points pts [n][3] (centre and max half-extent, computed in
 * double, rounded to float). A box with scale ≤ 0 or a non-finite
 * coordinate is TCB_ERR_INPUT; `what` names the cloud in the message. */
int tcb_cc_box_of_points(const float *pts, int n, const char *what, tcb_cc_frame_box *out,
                         tcb_error *err);

/* The box of frame f of seq, from its whole point pool (seq->pool_size
 * points; pools must be drawn). Errors (TCB_ERR_INPUT) name the sequence
 * and the frame: f out of range, no pools, a degenerate or non-finite
 * frame. */
int tcb_cc_frame_box_compute(const tcb_sequence *seq, int f, tcb_cc_frame_box *out,
                             tcb_error *err);

/* out[i] = (in[i] − center) / scale for n points [n][3]; in == out allowed.
 * Evaluated in double, rounded once to float. */
void tcb_cc_frame_box_apply(const tcb_cc_frame_box *box, const float *in, int n, float *out);

/* out[i] = in[i] · scale + center, the inverse of apply (to float rounding);
 * in == out allowed. */
void tcb_cc_frame_box_invert(const tcb_cc_frame_box *box, const float *in, int n, float *out);

/* ---- training augmentation (ShapeNetSeg.getAnItem) ---------------------- */

#define TCB_CC_ROT_RANGE_DEG 40.0 /* θ ∈ U(−20°, 20°): π / (360 / range) */
#define TCB_CC_ANISO_LO 0.75      /* anisotropic_scaling: torch.rand(1,3)/2 + 0.75 */
#define TCB_CC_ANISO_HI 1.25
#define TCB_CC_TRANSLATION 0.03   /* add_random_translation(scale=0.03) */
#define TCB_CC_SELFREC_SCALE 0.5  /* compute_loss_selfReconstruction: rand − 0.5 */

/* What one augmentation drew, for the self-reconstruction loss and logs. */
typedef struct tcb_cc_aug {
    double theta;   /* radians, U(−π/9, π/9) */
    float rot[9];   /* row-major rot_matrix = R_y(θ)ᵀ, as the CC code returns it */
    float scale[3]; /* anisotropic factors, U(0.75, 1.25) per axis */
    float shift[3]; /* translation, U(−0.03, 0.03) per axis */
} tcb_cc_aug;

/* rot[9] (row-major) = R_y(θ)ᵀ, where
 *     R_y(θ) = [[cos θ, 0, sin θ], [0, 1, 0], [−sin θ, 0, cos θ]]
 * is get_3D_rot_matrix(axis=1, θ); uniform_rotation_axis_matrix returns its
 * transpose, in float32, and points are rotated as points · rot. */
void tcb_cc_rot_matrix(double theta, float rot[9]);

/* Augments pts [n][3] (a cloud already in its frame box) in place, in the
 * CC order:
 *   a. rotation about the vertical axis y: θ = U(−π/9, π/9),
 *      pts ← pts · rot with rot = R_y(θ)ᵀ (uniform_rotation_axis);
 *   b. anisotropic scaling by U(0.75, 1.25) per axis, then the BoundingBox
 *      renormalization of the scaled cloud (centre its bounding box, divide
 *      by its largest half-extent);
 *   c. translation by U(−0.03, 0.03) per axis.
 * So the result has its bounding box centred within 0.03 of 0 per axis and
 * a largest half-extent of 1. Draw order from rng (tcb_rng_uniform), fixed:
 * θ, then the scales x, y, z, then the translations x, y, z (7 draws).
 * *aug (may be NULL) receives what was drawn; the caller keeps C's rot for
 * the self-reconstruction loss. A cloud whose scaled box is degenerate
 * (e.g. n < 2 distinct points) or not finite is TCB_ERR_INPUT (pts is then
 * partly transformed). */
int tcb_cc_augment(float *pts, int n, tcb_rng *rng, tcb_cc_aug *aug, tcb_error *err);

/* The self-reconstruction target of compute_loss_selfReconstruction:
 *     P4 = P3.bmm(rot_matrix.transpose(2, 1)); P4 = P4 + s ⊙ P4
 * for one shape: p3 [n][3] is the augmented third cloud C, rot its
 * rot_matrix (tcb_cc_aug.rot, = R_y(θ)ᵀ, so P3 · rotᵀ = P3 · R_y(θ) undoes
 * C's rotation), s [3] the per-axis factors of tcb_cc_selfrec_draw_scale:
 *     p4[i][j] = q_j + s_j · q_j,   q_j = (p3[i][0]·rot[j][0] + p3[i][1]·rot[j][1]) + p3[i][2]·rot[j][2]
 * in float, no renormalization (|p4| < 1.03 · (cos 20° + sin 20°) · 1.5 < 2).
 * p3 and p4 must not overlap. */
void tcb_cc_selfrec_target(const float *p3, int n, const float rot[9], const float s[3],
                           float *p4);

/* s[d] = U(−0.5, 0.5) for d = x, y, z, in that order (torch.rand(B,1,3) − 0.5,
 * one row per shape): the anisotropic scale 1 + s ∈ (0.5, 1.5). */
void tcb_cc_selfrec_draw_scale(tcb_rng *rng, float s[3]);

#endif
