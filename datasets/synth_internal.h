/* Internals of the embedded synthetic sequences (datasets/synth*.c), shared
 * only with their unit test. Not part of the public API.
 *
 * A body is a tree of bones; each bone is a tapered capsule of flesh that
 * rotates about its joint. The rest surface is the smooth union of the
 * capsules, polygonized once (tcb_synth_mesh.c); frames are made by linear-blend
 * skinning of that one mesh (tcb_synth_skin.c), so topology never changes.
 * Coordinates: x right, y up, the creature faces −z; the sagittal plane is
 * x = 0 and every bone off that plane has a mirror twin. */
#ifndef TCB_SYNTH_INTERNAL_H
#define TCB_SYNTH_INTERNAL_H

#include <stdint.h>

#include "tcb/error.h"

#define TCB_SYNTH_MAX_BONES 24

typedef struct tcb_synth_bone {
    int parent;   /* < own index; -1 for the root */
    int mirror;   /* index of the x → −x twin; itself on the midline */
    int side;     /* +1 (x > 0), −1 (x < 0) or 0 (midline) */
    float a[3];   /* rest joint: the bone rotates about this point */
    float b[3];   /* rest tip */
    float ra, rb; /* capsule radius at a and at b */
} tcb_synth_bone;

typedef struct tcb_synth_body {
    int n_bones;
    tcb_synth_bone bones[TCB_SYNTH_MAX_BONES];
    float blend;  /* smooth-union radius between capsules */
    float cell;   /* polygonization lattice spacing */
    int overflow; /* set when a bone did not fit in bones[] */
} tcb_synth_body;

/* One frame's articulation. Rotations are axis-angle vectors in rest-space
 * axes, applied about each bone's joint after its parent's motion. Stretch
 * factors scale a bone along (len) and across (rad) its own axis without
 * being inherited: they vary proportions per seed. */
typedef struct tcb_synth_pose {
    double rot[TCB_SYNTH_MAX_BONES][3];
    double len[TCB_SYNTH_MAX_BONES];
    double rad[TCB_SYNTH_MAX_BONES];
    double shift[3]; /* root translation */
} tcb_synth_pose;

/* Gait parameters of a periodic motion; each creature reads what it needs. */
typedef struct tcb_synth_gait {
    double period;  /* frames per cycle */
    double swing;   /* main limb swing amplitude, radians */
    double bend;    /* distal joint flexion amplitude, radians */
    double lead[4]; /* cycle offset of each limb (quadruped: LF, RF, LH, RH) */
    double bounce;  /* root vertical bob, body-length units */
} tcb_synth_gait;

/* ---- tcb_synth_body.c ------------------------------------------------------ */
void tcb_synth_body_init(tcb_synth_body *b, float blend, float cell);
/* Adds a midline bone; returns its index (−1 and sets overflow when full). */
int tcb_synth_body_add(tcb_synth_body *b, int parent, const float a[3], const float tip[3],
                       float ra, float rb);
/* Adds the bone on the +x side and its mirror twin right after it; returns
 * the +x index (the twin is that + 1). `parent` is the +x parent (its twin
 * parents the twin) or a midline bone. */
int tcb_synth_body_add_pair(tcb_synth_body *b, int parent, const float a[3], const float tip[3],
                            float ra, float rb);
/* Field of one capsule and of the whole body: < 0 inside, ≈ distance.
 * The body field is exactly mirror-symmetric: f(−x, y, z) == f(x, y, z). */
float tcb_synth_bone_field(const tcb_synth_bone *bone, const float p[3]);
float tcb_synth_body_field(const tcb_synth_body *b, const float p[3]);
/* Axis-aligned box that contains the body's surface, margin included. */
void tcb_synth_body_bounds(const tcb_synth_body *b, float margin, float lo[3], float hi[3]);

/* ---- tcb_synth_mesh.c ------------------------------------------------------ */
/* Closed, outward-oriented, connected triangle mesh of the body's rest
 * surface; verts [nv][3], faces [nf][3], malloc'ed, owned by the caller. */
int tcb_synth_mesh_build(const tcb_synth_body *b, float **verts, int *nv, int32_t **faces, int *nf,
                         tcb_error *err);

/* ---- tcb_synth_skin.c ------------------------------------------------------ */
#define TCB_SYNTH_SKIN_K 4 /* bones influencing one vertex */

typedef struct tcb_synth_skin {
    int n_verts;
    int32_t *bone; /* [n_verts][TCB_SYNTH_SKIN_K] */
    float *weight; /* [n_verts][TCB_SYNTH_SKIN_K], each row sums to 1 */
} tcb_synth_skin;

int tcb_synth_skin_bind(const tcb_synth_body *b, const float *verts, int nv, tcb_synth_skin *out,
                        tcb_error *err);
void tcb_synth_skin_free(tcb_synth_skin *s);
/* The rest pose: no rotation, unit stretch, no shift. */
void tcb_synth_pose_rest(tcb_synth_pose *p);
/* Sets bone i's rotation given in +x-side convention, mirrored for a −x
 * bone, so one limb law drives both sides. */
void tcb_synth_pose_rotate(tcb_synth_pose *p, const tcb_synth_body *b, int bone, double wx,
                           double wy, double wz);
/* out [nv][3] = rest [nv][3] skinned into pose p. */
void tcb_synth_skin_apply(const tcb_synth_body *b, const tcb_synth_skin *s, const tcb_synth_pose *p,
                          const float *rest, float *out);

/* ---- tcb_synth_quadruped.c / tcb_synth_humanoid.c ------------------------------ */
void tcb_synth_quadruped_body(tcb_synth_body *b);
void tcb_synth_quadruped_pose(const tcb_synth_body *b, const tcb_synth_gait *g, double phase,
                              tcb_synth_pose *p);
void tcb_synth_humanoid_body(tcb_synth_body *b);
void tcb_synth_humanoid_pose(const tcb_synth_body *b, const tcb_synth_gait *g, double phase,
                             tcb_synth_pose *p);

/* The quadruped giving way: pose at collapse progress s ∈ [0, 1] (gait
 * swing: leg splay, bend: leg fold, bounce: how far the body drops). */
void tcb_synth_quadruped_collapse_pose(const tcb_synth_body *b, const tcb_synth_gait *g, double s,
                                       tcb_synth_pose *p);

/* ---- tcb_synth_collapse.c ------------------------------------------------ */
/* out [nv][3] = rest with its flesh shrunk towards the skeleton by the
 * collapse's share at progress `amount` ∈ [0, 1] (0: rest unchanged). */
void tcb_synth_collapse_deflate(const tcb_synth_body *b, const tcb_synth_skin *s,
                                const float *rest, double amount, float *out);
/* In place on a posed frame: squash towards the ground, widen near it
 * about centre (x, z), pile what sank below y = 0 into a thin soft layer. */
void tcb_synth_collapse_sag(float *verts, int nv, const double centre[2], double amount);

/* ---- synth.c ----------------------------------------------------------- */
/* Rest mesh of the named sequence's body (seed-independent canonical
 * proportions), for tests; malloc'ed arrays owned by the caller. */
int tcb_synth_rest_mesh(const char *name, float **verts, int *nv, int32_t **faces, int *nf,
                        tcb_error *err);

#endif
