/* CC per-frame normalization and training augmentation; see augment.h.
 * Followed: auxiliary/normalize_points.py and ShapeNetSeg.getAnItem in
 * auxiliary/dataset_shapenet.py of ThibaultGROUEIX/CycleConsistentDeformation. */
#include "methods/cycle/augment.h"

#include <math.h>
#include <stddef.h>
#include <stdio.h>

/* normalize_points.center_bounding_box + BoundingBox: centre = (min + max)/2,
 * divisor = max over axes of (max − min)/2 (the code calls it "diameter"). */
int tcb_cc_box_of_points(const float *pts, int n, const char *what, tcb_cc_frame_box *out,
                         tcb_error *err)
{
    *out = (tcb_cc_frame_box){{0.0f, 0.0f, 0.0f}, 0.0f};
    if (n < 1 || !pts)
        return tcb_fail(err, TCB_ERR_INPUT, "cc: %s has no points", what ? what : "cloud");
    double lo[3], hi[3];
    for (int d = 0; d < 3; d++) lo[d] = INFINITY, hi[d] = -INFINITY;
    for (int i = 0; i < n; i++)
        for (int d = 0; d < 3; d++) {
            double x = pts[3 * (size_t)i + d];
            if (!isfinite(x))
                return tcb_fail(err, TCB_ERR_INPUT, "cc: %s: point %d is not finite",
                                what ? what : "cloud", i);
            if (x < lo[d]) lo[d] = x;
            if (x > hi[d]) hi[d] = x;
        }
    double scale = 0.0;
    for (int d = 0; d < 3; d++) {
        out->center[d] = (float)(0.5 * (lo[d] + hi[d]));
        double half = 0.5 * (hi[d] - lo[d]);
        if (half > scale) scale = half;
    }
    out->scale = (float)scale;
    if (!(out->scale > 0.0f) || !isfinite(out->scale))
        return tcb_fail(err, TCB_ERR_INPUT,
                        "cc: %s has a degenerate bounding box (largest half-extent %g)",
                        what ? what : "cloud", scale);
    return TCB_OK;
}

int tcb_cc_frame_box_compute(const tcb_sequence *seq, int f, tcb_cc_frame_box *out,
                             tcb_error *err)
{
    if (f < 0 || f >= seq->n_frames)
        return tcb_fail(err, TCB_ERR_INPUT, "cc: sequence %s has no frame %d (%d frames)",
                        seq->name, f, seq->n_frames);
    if (seq->pool_size < 1 || !seq->pools)
        return tcb_fail(err, TCB_ERR_INPUT, "cc: sequence %s has no point pools", seq->name);
    char what[TCB_NAME_MAX + 32];
    snprintf(what, sizeof what, "frame %d of %s", f, seq->name);
    return tcb_cc_box_of_points(tcb_seq_pool(seq, f), seq->pool_size, what, out, err);
}

void tcb_cc_frame_box_apply(const tcb_cc_frame_box *box, const float *in, int n, float *out)
{
    const double s = box->scale;
    for (size_t i = 0; i < 3 * (size_t)(n > 0 ? n : 0); i++)
        out[i] = (float)(((double)in[i] - (double)box->center[i % 3]) / s);
}

void tcb_cc_frame_box_invert(const tcb_cc_frame_box *box, const float *in, int n, float *out)
{
    const double s = box->scale;
    for (size_t i = 0; i < 3 * (size_t)(n > 0 ? n : 0); i++)
        out[i] = (float)((double)in[i] * s + (double)box->center[i % 3]);
}

/* get_3D_rot_matrix(axis=1, θ) = [[c, 0, s], [0, 1, 0], [−s, 0, c]];
 * uniform_rotation_axis_matrix returns np.transpose of it as float32. */
void tcb_cc_rot_matrix(double theta, float rot[9])
{
    const double c = cos(theta), s = sin(theta);
    const double R[9] = {c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c};
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) rot[3 * i + j] = (float)R[3 * j + i];
}

/* pts ← pts · M (row vectors, M row-major), as torch.mm(points, rot_matrix). */
static void mul_right(float *pts, int n, const float M[9])
{
    for (int i = 0; i < n; i++) {
        float *p = pts + 3 * (size_t)i;
        const float x = p[0], y = p[1], z = p[2];
        for (int j = 0; j < 3; j++) p[j] = (x * M[j] + y * M[3 + j]) + z * M[6 + j];
    }
}

int tcb_cc_augment(float *pts, int n, tcb_rng *rng, tcb_cc_aug *aug, tcb_error *err)
{
    tcb_cc_aug a;
    /* Draw order (fixed): θ, scale x/y/z, translation x/y/z. */
    const double half_range = M_PI * (TCB_CC_ROT_RANGE_DEG / 360.0); /* π / scale_factor */
    a.theta = (2.0 * tcb_rng_uniform(rng) - 1.0) * half_range;
    for (int d = 0; d < 3; d++)
        a.scale[d] =
            (float)(TCB_CC_ANISO_LO + (TCB_CC_ANISO_HI - TCB_CC_ANISO_LO) * tcb_rng_uniform(rng));
    for (int d = 0; d < 3; d++)
        a.shift[d] = (float)((2.0 * tcb_rng_uniform(rng) - 1.0) * TCB_CC_TRANSLATION);
    tcb_cc_rot_matrix(a.theta, a.rot);
    if (aug) *aug = a;

    /* a. uniform_rotation_axis(points, axis=1, range_rot=40): points · rot. */
    mul_right(pts, n, a.rot);
    /* b. anisotropic_scaling, then the BoundingBox normalization_function. */
    for (int i = 0; i < n; i++)
        for (int d = 0; d < 3; d++) pts[3 * (size_t)i + d] *= a.scale[d];
    tcb_cc_frame_box box = {{0.0f, 0.0f, 0.0f}, 1.0f};
    int rc = tcb_cc_box_of_points(pts, n, "augmented cloud", &box, err);
    if (rc) return rc;
    tcb_cc_frame_box_apply(&box, pts, n, pts);
    /* c. add_random_translation(points, scale=0.03). */
    for (int i = 0; i < n; i++)
        for (int d = 0; d < 3; d++) pts[3 * (size_t)i + d] += a.shift[d];
    return TCB_OK;
}

/* compute_loss_selfReconstruction: P4 = P3.bmm(rot_matrix.transpose(2, 1)),
 * i.e. p4_j = Σ_k p3_k · rot[j][k]; then P4 = P4 + scale * P4. */
void tcb_cc_selfrec_target(const float *p3, int n, const float rot[9], const float s[3],
                           float *p4)
{
    for (int i = 0; i < n; i++) {
        const float *p = p3 + 3 * (size_t)i;
        float *q = p4 + 3 * (size_t)i;
        for (int j = 0; j < 3; j++) {
            float v = (p[0] * rot[3 * j] + p[1] * rot[3 * j + 1]) + p[2] * rot[3 * j + 2];
            q[j] = v + s[j] * v;
        }
    }
}

void tcb_cc_selfrec_draw_scale(tcb_rng *rng, float s[3])
{
    for (int d = 0; d < 3; d++) s[d] = (float)(tcb_rng_uniform(rng) - TCB_CC_SELFREC_SCALE);
}
