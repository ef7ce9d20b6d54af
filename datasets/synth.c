/* The catalogue of embedded synthetic sequences and their generation:
 * polygonize the body once, bind the skin, then pose every frame. The seed
 * jitters the start phase, tempo, amplitudes and bone proportions (per
 * left/right pair, so symmetry holds); the mesh itself never depends on it. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "datasets/synth_internal.h"
#include "tcb/synth.h"

#define DEFAULT_FRAMES    40
#define MAX_FRAMES        100000
#define PHASE_JITTER      0.1  /* cycles */
#define TEMPO_JITTER      0.05 /* relative */
#define AMPLITUDE_JITTER  0.08 /* relative */
#define PROPORTION_JITTER 0.04 /* relative, per bone length and thickness */

typedef struct synth_entry {
    const char *name;
    const char *description;
    void (*body)(tcb_synth_body *b);
    void (*pose)(const tcb_synth_body *b, const tcb_synth_gait *g, double phase, tcb_synth_pose *p);
    tcb_synth_gait gait; /* period, swing, bend, lead[LF, RF, LH, RH], bounce */
    int collapses;       /* 1: `pose` takes the progress s ∈ [0, 1] of one collapse over the
                          * whole sequence, not a cycle phase; the flesh deflates and sags
                          * (tcb_synth_collapse_*) */
} synth_entry;

static const synth_entry catalogue[] = {
    /* Swing amplitudes are capped by clearance: in a trot the legs of one
     * side swing in antiphase, and beyond ~0.3 rad (with jitter) the
     * forward hind paw meets the folded front leg. */
    {"quadruped_walk",
     "quadruped walk cycle (lateral-sequence footfalls), linear-blend skinned",
     tcb_synth_quadruped_body,
     tcb_synth_quadruped_pose,
     {34.0, 0.28, 0.5, {0.25, 0.75, 0.0, 0.5}, 0.008},
     0},
    {"quadruped_trot",
     "the same quadruped trotting (diagonal leg pairs): faster, higher steps, more bounce",
     tcb_synth_quadruped_body,
     tcb_synth_quadruped_pose,
     {24.0, 0.3, 0.7, {0.0, 0.5, 0.5, 0.0}, 0.015},
     0},
    {"humanoid_jacks",
     "biped doing jumping jacks: arms and legs abduct together, hopping",
     tcb_synth_humanoid_body,
     tcb_synth_humanoid_pose,
     {28.0, 1.9, 0.25, {0.0, 0.0, 0.0, 0.0}, 0.04},
     0},
    /* The stress test's kind of motion (the paper's Table 10): far from
     * isometric by the end (docs/datasets.md gives its distortion). */
    {"quadruped_collapse",
     "the quadruped collapsing: legs splay and fold, the flesh deflates and sags onto the "
     "ground, folding over itself; strongly non-isometric",
     tcb_synth_quadruped_body,
     tcb_synth_quadruped_collapse_pose,
     {0.0, 1.1, 1.5, {0.0, 0.0, 0.0, 0.0}, 0.40},
     1},
};

#define N_ENTRIES ((int)(sizeof catalogue / sizeof catalogue[0]))

int tcb_synth_count(void) { return N_ENTRIES; }

const char *tcb_synth_name(int k) { return k >= 0 && k < N_ENTRIES ? catalogue[k].name : NULL; }

const char *tcb_synth_description(int k)
{
    return k >= 0 && k < N_ENTRIES ? catalogue[k].description : NULL;
}

static const synth_entry *find_entry(const char *name, tcb_error *err)
{
    for (int k = 0; name && k < N_ENTRIES; k++)
        if (!strcmp(catalogue[k].name, name)) return &catalogue[k];
    char known[256] = "";
    for (int k = 0; k < N_ENTRIES; k++) {
        size_t len = strlen(known);
        snprintf(known + len, sizeof known - len, "%s%s", k ? ", " : "", catalogue[k].name);
    }
    tcb_fail(err, TCB_ERR_INPUT, "unknown synthetic sequence '%s' (known: %s)",
             name ? name : "(null)", known);
    return NULL;
}

static int build_body(const synth_entry *e, tcb_synth_body *b, tcb_error *err)
{
    e->body(b);
    if (b->overflow)
        return tcb_fail(err, TCB_ERR_INTERNAL, "synthetic body %s has more than %d bones", e->name,
                        TCB_SYNTH_MAX_BONES);
    return TCB_OK;
}

int tcb_synth_rest_mesh(const char *name, float **verts, int *nv, int32_t **faces, int *nf,
                        tcb_error *err)
{
    const synth_entry *e = find_entry(name, err);
    if (!e) return TCB_ERR_INPUT;
    tcb_synth_body b;
    int rc = build_body(e, &b, err);
    return rc ? rc : tcb_synth_mesh_build(&b, verts, nv, faces, nf, err);
}

static double jitter(tcb_rng *r, double amount)
{
    return 1.0 + amount * (2.0 * tcb_rng_uniform(r) - 1.0);
}

/* The seed's share of the motion: gait tempo/amplitudes, start phase and
 * the stretch factors of every bone (twins share theirs). */
static double vary(const tcb_synth_body *b, uint64_t seed, const char *name, tcb_synth_gait *g,
                   tcb_synth_pose *stretch)
{
    tcb_rng r;
    tcb_rng_seed_stream(&r, seed, name);
    double phase0 = PHASE_JITTER * tcb_rng_uniform(&r);
    g->period *= jitter(&r, TEMPO_JITTER);
    g->swing *= jitter(&r, AMPLITUDE_JITTER);
    g->bend *= jitter(&r, AMPLITUDE_JITTER);
    tcb_synth_pose_rest(stretch);
    for (int i = 0; i < b->n_bones; i++) {
        int m = b->bones[i].mirror;
        if (m < i) continue;
        stretch->len[i] = stretch->len[m] = jitter(&r, PROPORTION_JITTER);
        stretch->rad[i] = stretch->rad[m] = jitter(&r, PROPORTION_JITTER);
    }
    return phase0;
}

/* Progress of a collapse at frame f: eased in and out, so it starts and
 * ends at rest. */
static double collapse_progress(int f, int n_frames)
{
    double t = n_frames > 1 ? (double)f / (n_frames - 1) : 0.0;
    return t * t * (3.0 - 2.0 * t);
}

/* Horizontal (x, z) centroid of the rest mesh: where a collapse spreads from. */
static void rest_centre(const float *rest, int nv, double centre[2])
{
    double sx = 0.0, sz = 0.0;
    for (int v = 0; v < nv; v++) sx += rest[3 * (size_t)v], sz += rest[3 * (size_t)v + 2];
    centre[0] = sx / nv;
    centre[1] = sz / nv;
}

/* Frame f of a collapsing entry into out [nv][3]; scratch [nv][3]. */
static void collapse_frame(const synth_entry *e, const tcb_synth_body *b, const tcb_synth_skin *skin,
                           const tcb_synth_gait *g, const tcb_synth_pose *stretch, const float *rest,
                           double s, float *scratch, float *out)
{
    tcb_synth_pose p = *stretch;
    e->pose(b, g, s, &p);
    tcb_synth_collapse_deflate(b, skin, rest, s, scratch);
    tcb_synth_skin_apply(b, skin, &p, scratch, out);
    double centre[2];
    rest_centre(rest, skin->n_verts, centre);
    tcb_synth_collapse_sag(out, skin->n_verts, centre, s);
}

static int animate(const synth_entry *e, uint64_t seed, int n_frames, tcb_sequence *out,
                   tcb_error *err)
{
    tcb_synth_body b;
    float *rest = NULL;
    int32_t *faces = NULL;
    tcb_synth_skin skin = {0, NULL, NULL};
    int nv, nf;
    int rc = build_body(e, &b, err);
    if (!rc) rc = tcb_synth_mesh_build(&b, &rest, &nv, &faces, &nf, err);
    if (!rc) rc = tcb_synth_skin_bind(&b, rest, nv, &skin, err);
    if (!rc) rc = tcb_sequence_alloc(out, e->name, n_frames, nv, nf, err);
    float *scratch = NULL;
    if (!rc && e->collapses && !(scratch = malloc((size_t)nv * 3 * sizeof *scratch)))
        rc = tcb_fail(err, TCB_ERR_NOMEM, "synthetic sequence %s: out of memory", e->name);
    if (!rc) {
        memcpy(out->faces, faces, (size_t)nf * 3 * sizeof *faces);
        tcb_synth_gait g = e->gait;
        tcb_synth_pose stretch;
        double phase0 = vary(&b, seed, e->name, &g, &stretch);
        for (int f = 0; f < n_frames; f++) {
            float *frame = out->verts + (size_t)f * (size_t)nv * 3;
            tcb_synth_pose p = stretch;
            if (e->collapses) {
                collapse_frame(e, &b, &skin, &g, &stretch, rest, collapse_progress(f, n_frames),
                               scratch, frame);
                continue;
            }
            e->pose(&b, &g, phase0 + f / g.period, &p);
            tcb_synth_skin_apply(&b, &skin, &p, rest, frame);
        }
    }
    free(scratch);
    tcb_synth_skin_free(&skin);
    free(rest);
    free(faces);
    return rc;
}

int tcb_synth_generate(const char *name, uint64_t seed, int n_frames, tcb_sequence *out,
                       tcb_error *err)
{
    memset(out, 0, sizeof *out);
    const synth_entry *e = find_entry(name, err);
    if (!e) return TCB_ERR_INPUT;
    if (n_frames <= 0) n_frames = DEFAULT_FRAMES;
    if (n_frames > MAX_FRAMES)
        return tcb_fail(err, TCB_ERR_INPUT,
                        "synthetic sequence %s: %d frames requested, at most %d", name, n_frames,
                        MAX_FRAMES);
    return animate(e, seed, n_frames, out, err);
}
