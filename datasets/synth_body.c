/* Synthetic bodies as trees of tapered capsules and their implicit field. */
#include <math.h>
#include <string.h>

#include "datasets/synth_internal.h"

void tcb_synth_body_init(tcb_synth_body *b, float blend, float cell)
{
    memset(b, 0, sizeof *b);
    b->blend = blend;
    b->cell = cell;
}

static int add_bone(tcb_synth_body *b, int parent, int side, const float a[3], const float tip[3],
                    float ra, float rb)
{
    /* Bodies are constants in synth_*.c; overflowing the table is a
     * programming error, recorded for the generator to report. */
    if (b->n_bones >= TCB_SYNTH_MAX_BONES) {
        b->overflow = 1;
        return -1;
    }
    int i = b->n_bones++;
    tcb_synth_bone *bone = &b->bones[i];
    bone->parent = parent;
    bone->mirror = i;
    bone->side = side;
    memcpy(bone->a, a, sizeof bone->a);
    memcpy(bone->b, tip, sizeof bone->b);
    bone->ra = ra;
    bone->rb = rb;
    return i;
}

int tcb_synth_body_add(tcb_synth_body *b, int parent, const float a[3], const float tip[3],
                       float ra, float rb)
{
    return add_bone(b, parent, 0, a, tip, ra, rb);
}

int tcb_synth_body_add_pair(tcb_synth_body *b, int parent, const float a[3], const float tip[3],
                            float ra, float rb)
{
    float ma[3] = {-a[0], a[1], a[2]}, mt[3] = {-tip[0], tip[1], tip[2]};
    int twin_parent = parent >= 0 ? b->bones[parent].mirror : -1;
    int i = add_bone(b, parent, +1, a, tip, ra, rb);
    int j = add_bone(b, twin_parent, -1, ma, mt, ra, rb);
    if (i < 0 || j < 0) return -1;
    b->bones[i].mirror = j;
    b->bones[j].mirror = i;
    return i;
}

float tcb_synth_bone_field(const tcb_synth_bone *bone, const float p[3])
{
    /* Distance to the segment minus the radius interpolated at the closest
     * point: exact for a plain capsule, close enough for mild tapers. */
    float d[3], u[3];
    for (int k = 0; k < 3; k++) {
        d[k] = p[k] - bone->a[k];
        u[k] = bone->b[k] - bone->a[k];
    }
    float uu = u[0] * u[0] + u[1] * u[1] + u[2] * u[2];
    float t = uu > 0.0f ? (d[0] * u[0] + d[1] * u[1] + d[2] * u[2]) / uu : 0.0f;
    t = t < 0.0f ? 0.0f : (t > 1.0f ? 1.0f : t);
    float e[3] = {d[0] - t * u[0], d[1] - t * u[1], d[2] - t * u[2]};
    return sqrtf(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]) - (bone->ra + t * (bone->rb - bone->ra));
}

/* Polynomial smooth minimum (Quilez): a fillet of radius ~k where two
 * capsules meet. Symmetric in (a, b) bit for bit, which keeps the body
 * field exactly mirror-symmetric. */
static float smooth_min(float a, float b, float k)
{
    float h = k - fabsf(a - b);
    if (h <= 0.0f) return fminf(a, b);
    h /= k;
    return fminf(a, b) - h * h * k * 0.25f;
}

float tcb_synth_body_field(const tcb_synth_body *b, const float p[3])
{
    /* Twins are merged with each other before joining the fold, so the fold
     * sees the same operands at p and at its mirror image. (Mirroring only
     * negates x, and negation is exact in IEEE arithmetic, so a bone's
     * field at p equals its twin's field at the mirror of p.) */
    float f = INFINITY;
    for (int i = 0; i < b->n_bones; i++) {
        const tcb_synth_bone *bone = &b->bones[i];
        if (bone->mirror < i) continue;
        float g = tcb_synth_bone_field(bone, p);
        if (bone->mirror != i)
            g = smooth_min(g, tcb_synth_bone_field(&b->bones[bone->mirror], p), b->blend);
        f = smooth_min(f, g, b->blend);
    }
    return f;
}

void tcb_synth_body_bounds(const tcb_synth_body *b, float margin, float lo[3], float hi[3])
{
    for (int k = 0; k < 3; k++) {
        lo[k] = INFINITY;
        hi[k] = -INFINITY;
    }
    for (int i = 0; i < b->n_bones; i++) {
        const tcb_synth_bone *bone = &b->bones[i];
        float r = fmaxf(bone->ra, bone->rb) + margin;
        for (int k = 0; k < 3; k++) {
            lo[k] = fminf(lo[k], fminf(bone->a[k], bone->b[k]) - r);
            hi[k] = fmaxf(hi[k], fmaxf(bone->a[k], bone->b[k]) + r);
        }
    }
}
