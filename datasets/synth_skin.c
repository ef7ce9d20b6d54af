/* Linear-blend skinning of a synthetic body: weights from the capsule
 * fields at rest, bone transforms from a pose, blended vertex positions. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "datasets/synth_internal.h"

/* A bone's weight falls to zero once its capsule is this many blend radii
 * farther from the vertex than the nearest capsule: joints then bend over
 * about a limb radius, like the fillets of the smooth union. */
#define FALLOFF_BLENDS 2.0f

static void bind_vertex(const tcb_synth_body *b, const float p[3], int32_t *bone, float *weight)
{
    float s[TCB_SYNTH_MAX_BONES], s_min = INFINITY;
    for (int i = 0; i < b->n_bones; i++) {
        s[i] = tcb_synth_bone_field(&b->bones[i], p);
        s_min = fminf(s_min, s[i]);
    }
    float falloff = FALLOFF_BLENDS * b->blend;
    for (int k = 0; k < TCB_SYNTH_SKIN_K; k++) {
        bone[k] = 0;
        weight[k] = 0.0f;
    }
    /* Keep the TCB_SYNTH_SKIN_K heaviest by insertion; the nearest bone has
     * weight 1 before normalization, so the sum is never zero. */
    for (int i = 0; i < b->n_bones; i++) {
        float w = fmaxf(0.0f, 1.0f - (s[i] - s_min) / falloff);
        w *= w;
        int k = TCB_SYNTH_SKIN_K;
        while (k > 0 && weight[k - 1] < w) k--;
        if (k == TCB_SYNTH_SKIN_K) continue;
        memmove(bone + k + 1, bone + k, (size_t)(TCB_SYNTH_SKIN_K - 1 - k) * sizeof *bone);
        memmove(weight + k + 1, weight + k, (size_t)(TCB_SYNTH_SKIN_K - 1 - k) * sizeof *weight);
        bone[k] = i;
        weight[k] = w;
    }
    float total = 0.0f;
    for (int k = 0; k < TCB_SYNTH_SKIN_K; k++) total += weight[k];
    for (int k = 0; k < TCB_SYNTH_SKIN_K; k++) weight[k] /= total;
}

int tcb_synth_skin_bind(const tcb_synth_body *b, const float *verts, int nv, tcb_synth_skin *out,
                        tcb_error *err)
{
    out->n_verts = nv;
    out->bone = malloc((size_t)nv * TCB_SYNTH_SKIN_K * sizeof *out->bone);
    out->weight = malloc((size_t)nv * TCB_SYNTH_SKIN_K * sizeof *out->weight);
    if (!out->bone || !out->weight) {
        tcb_synth_skin_free(out);
        return tcb_fail(err, TCB_ERR_NOMEM, "out of memory binding a synthetic skin");
    }
    for (int v = 0; v < nv; v++)
        bind_vertex(b, verts + 3 * (size_t)v, out->bone + (size_t)v * TCB_SYNTH_SKIN_K,
                    out->weight + (size_t)v * TCB_SYNTH_SKIN_K);
    return TCB_OK;
}

void tcb_synth_skin_free(tcb_synth_skin *s)
{
    free(s->bone);
    free(s->weight);
    s->bone = NULL;
    s->weight = NULL;
}

void tcb_synth_pose_rest(tcb_synth_pose *p)
{
    memset(p, 0, sizeof *p);
    for (int i = 0; i < TCB_SYNTH_MAX_BONES; i++) p->len[i] = p->rad[i] = 1.0;
}

void tcb_synth_pose_rotate(tcb_synth_pose *p, const tcb_synth_body *b, int bone, double wx,
                           double wy, double wz)
{
    /* Conjugating a rotation by the mirror diag(−1, 1, 1) keeps the x
     * component of its axis-angle vector and negates the others. */
    double m = b->bones[bone].side < 0 ? -1.0 : 1.0;
    p->rot[bone][0] = wx;
    p->rot[bone][1] = m * wy;
    p->rot[bone][2] = m * wz;
}

/* Rotation matrix (row-major 3×3) of an axis-angle vector (Rodrigues). */
static void rotation(const double w[3], double R[9])
{
    double th = sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
    double k[3] = {0.0, 0.0, 0.0};
    if (th > 0.0)
        for (int i = 0; i < 3; i++) k[i] = w[i] / th;
    double c = cos(th), s = sin(th), t = 1.0 - c;
    R[0] = c + t * k[0] * k[0];
    R[1] = t * k[0] * k[1] - s * k[2];
    R[2] = t * k[0] * k[2] + s * k[1];
    R[3] = t * k[1] * k[0] + s * k[2];
    R[4] = c + t * k[1] * k[1];
    R[5] = t * k[1] * k[2] - s * k[0];
    R[6] = t * k[2] * k[0] - s * k[1];
    R[7] = t * k[2] * k[1] + s * k[0];
    R[8] = c + t * k[2] * k[2];
}

static void matmul(const double A[9], const double B[9], double C[9])
{
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            C[3 * i + j] = A[3 * i] * B[j] + A[3 * i + 1] * B[3 + j] + A[3 * i + 2] * B[6 + j];
}

/* Bone i maps a rest point x to o[i] + lin[i]·(x − a_i). Its rotation
 * composes with its parent's; its stretch does not, but its joint rides on
 * the parent's full map so limbs stay attached. */
static void bone_maps(const tcb_synth_body *b, const tcb_synth_pose *p, double o[][3],
                      double lin[][9], double rot[][9])
{
    for (int i = 0; i < b->n_bones; i++) {
        const tcb_synth_bone *bone = &b->bones[i];
        double R[9], u[3], uu = 0.0;
        rotation(p->rot[i], R);
        int q = bone->parent;
        if (q < 0) {
            memcpy(rot[i], R, sizeof R);
            for (int k = 0; k < 3; k++) o[i][k] = bone->a[k] + p->shift[k];
        } else {
            matmul(rot[q], R, rot[i]);
            const float *aq = b->bones[q].a;
            double d[3] = {bone->a[0] - aq[0], bone->a[1] - aq[1], bone->a[2] - aq[2]};
            for (int k = 0; k < 3; k++)
                o[i][k] = o[q][k] + lin[q][3 * k] * d[0] + lin[q][3 * k + 1] * d[1] +
                          lin[q][3 * k + 2] * d[2];
        }
        for (int k = 0; k < 3; k++) {
            u[k] = (double)bone->b[k] - bone->a[k];
            uu += u[k] * u[k];
        }
        double S[9]; /* rad·I + (len − rad)·û ûᵀ */
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 3; c++)
                S[3 * r + c] = (r == c ? p->rad[i] : 0.0) +
                               (uu > 0.0 ? (p->len[i] - p->rad[i]) * u[r] * u[c] / uu : 0.0);
        matmul(rot[i], S, lin[i]);
    }
}

void tcb_synth_skin_apply(const tcb_synth_body *b, const tcb_synth_skin *s, const tcb_synth_pose *p,
                          const float *rest, float *out)
{
    double o[TCB_SYNTH_MAX_BONES][3], lin[TCB_SYNTH_MAX_BONES][9], rot[TCB_SYNTH_MAX_BONES][9];
    bone_maps(b, p, o, lin, rot);
    for (int v = 0; v < s->n_verts; v++) {
        const float *x = rest + 3 * (size_t)v;
        double y[3] = {0.0, 0.0, 0.0};
        for (int j = 0; j < TCB_SYNTH_SKIN_K; j++) {
            int i = s->bone[(size_t)v * TCB_SYNTH_SKIN_K + j];
            double w = s->weight[(size_t)v * TCB_SYNTH_SKIN_K + j];
            const float *a = b->bones[i].a;
            double d[3] = {x[0] - a[0], x[1] - a[1], x[2] - a[2]};
            for (int k = 0; k < 3; k++)
                y[k] += w * (o[i][k] + lin[i][3 * k] * d[0] + lin[i][3 * k + 1] * d[1] +
                             lin[i][3 * k + 2] * d[2]);
        }
        for (int k = 0; k < 3; k++) out[3 * (size_t)v + k] = (float)y[k];
    }
}
