/* tcbench — a deforming-shape sequence: K frames of one mesh topology.
 *
 * Vertex k is the same surface point in every frame, so vertex ids are the
 * ground-truth correspondences. A sequence may consist of several blocks of
 * consecutive frames (DFAUST: one per subject, tcb/block.h); pairs stay
 * inside a block. After loading, a sequence is normalized
 * (reference-protocol §1.3) and carries per frame a pool of area-uniform
 * surface samples from which methods draw their input clouds (§1.2).
 *
 * A sequence of points alone (Occupancy Flow's pcl_seq) has no faces
 * (n_faces 0, faces NULL): its pools are drawn from its vertices, and what
 * needs a surface (the geodesic error, the reconstruction metrics, GT
 * normals) is not computed for it.
 *
 * Ownership: a tcb_sequence owns all its arrays; tcb_sequence_free releases
 * them. Methods receive `const tcb_sequence *` and must not keep pointers
 * into it beyond `destroy`. */
#ifndef TCB_SEQUENCE_H
#define TCB_SEQUENCE_H

#include <stddef.h>
#include <stdint.h>

#include "tcb/block.h"
#include "tcb/error.h"
#include "tcb/progress.h"
#include "tcb/rng.h"

#ifdef __cplusplus
extern "C" {
#endif

#define TCB_NAME_MAX 128
#define TCB_DEFAULT_POOL_SIZE 10000
#define TCB_DEFAULT_INPUT_POINTS 2500

typedef enum tcb_normalization {
    TCB_NORM_NONE = 0,        /* raw coordinates (DFAUST) */
    TCB_NORM_FIRST_FRAME = 1, /* ANIM: centre on frame 0's vertex centroid, divide by its largest bbox extent */
    TCB_NORM_PER_FRAME = 2,   /* AMA-like: each frame centred on its own surface centroid, no scaling */
    TCB_NORM_CLIP_BBOX = 3,   /* Neu-PiG, PDG: centre of the box of every frame's vertices, divided by
                               * half its largest extent, times 0.95 (their src/io/) */
    TCB_NORM_FIRST_FRAME_DIAG = 4 /* DynoSurf: frame 0's vertex mean subtracted, divided by the
                                   * diagonal of frame 0's bounding box (its code/dataset.py) */
} tcb_normalization;

/* The margin of TCB_NORM_CLIP_BBOX: the sequence fills 95 % of [-1, 1]³. */
#define TCB_CLIP_BBOX_MARGIN 0.95

/* The normals that come with a method's input clouds ("evaluation.input_normals"). */
typedef enum tcb_input_normals {
    TCB_INPUT_NORMALS_NONE = 0,     /* points only (the ICCV'21 protocol) */
    TCB_INPUT_NORMALS_GT = 1,       /* the unit normal of the GT face each point was sampled on */
    TCB_INPUT_NORMALS_ESTIMATED = 2 /* estimated from the cloud alone (PCA, oriented) */
} tcb_input_normals;

typedef struct tcb_sequence {
    char name[TCB_NAME_MAX];
    int n_frames;
    int n_verts;
    int n_faces;
    float *verts;       /* [n_frames][n_verts][3] GT vertices, normalized */
    int32_t *faces;     /* [n_faces][3] triangles shared by every frame */
    double *areas;      /* [n_frames] GT surface area, normalized units */
    int pool_size;      /* samples per frame; 0 until pools are drawn */
    float *pools;       /* [n_frames][pool_size][3] area-uniform samples */
    tcb_normalization norm;
    double norm_scale;  /* FIRST_FRAME, CLIP_BBOX, FIRST_FRAME_DIAG: the divisor; 1 otherwise */
    double *norm_shift; /* [n_frames][3] subtracted before scaling */
    double *yaw;        /* [n_frames] radians about y applied after the normalization
                         * (rotation alignment, tcb/align.h); NULL when not aligned */
    /* The dataset's input protocol (§1.2), set by the harness from the
     * config: a method's input cloud is input_points draws from a pool,
     * with or without replacement (see tcb_sequence_draw_points). */
    int input_points;
    int draw_with_replacement;
    int n_blocks;       /* 0: one block, the whole sequence (every source but DFAUST) */
    tcb_block *blocks;  /* [n_blocks], tiling [0, n_frames) in order */
    /* Appended last (plug-ins built before it never read it): the normals
     * that come with input clouds, set by the harness from the config; a
     * method that takes normals gets them with tcb_sequence_input_normals
     * (tcb/input_normals.h). */
    tcb_input_normals input_normals;
    /* Tracked GT points besides the vertices (the authors' clip folders'
     * pcl_seqs: point k is the same surface point in every frame), moved by
     * the normalization and alignment as the vertices; DynoSurf's Corr
     * matches against them. 0, NULL when the source has none. */
    int n_track;
    float *track;       /* [n_frames][n_track][3] */
} tcb_sequence;

static inline const float *tcb_seq_frame(const tcb_sequence *s, int f)
{
    return s->verts + (size_t)f * (size_t)s->n_verts * 3;
}

/* The block of frame f: its index and frames [*lo, *hi) (tcb_block_find). */
static inline int tcb_seq_block_of(const tcb_sequence *s, int f, int *lo, int *hi)
{
    return tcb_block_find(s->blocks, s->n_blocks, s->n_frames, f, lo, hi);
}

static inline const float *tcb_seq_pool(const tcb_sequence *s, int f)
{
    return s->pools + (size_t)f * (size_t)s->pool_size * 3;
}

/* Raw frames from a directory of OBJ files, ordered by the (last) number in
 * each file name. Frames whose vertex count or faces differ from the first
 * frame are an error naming both files. Fewer than two frames is an error. */
int tcb_sequence_read_objdir(const char *dir, tcb_sequence *out, tcb_error *err);

/* The frame count and the first frame's vertex count of an OBJ directory,
 * reading one file: what a dry run needs to size the work. */
int tcb_sequence_probe_objdir(const char *dir, int *n_frames, int *n_verts, tcb_error *err);

/* Allocate an empty sequence with the given sizes (verts/faces uninitialised). */
int tcb_sequence_alloc(tcb_sequence *s, const char *name, int n_frames, int n_verts,
                       int n_faces, tcb_error *err);

/* Apply a normalization in place (to raw vertices) and compute areas. */
int tcb_sequence_normalize(tcb_sequence *s, tcb_normalization mode, tcb_error *err);

/* Draw pool_size area-uniform samples per frame from a stream seeded by
 * (seed, sequence name). Deterministic. */
int tcb_sequence_sample_pools(tcb_sequence *s, int pool_size, uint64_t seed,
                              tcb_error *err);

/* n input points from frame f's pool: without replacement (a random
 * permutation's first n, as ANIM) or with replacement (AMA, DFAUST). */
int tcb_sequence_draw_points(const tcb_sequence *s, int f, int n, int with_replacement,
                             tcb_rng *rng, float *out, tcb_error *err);

/* FNV-1a of everything a method is given (name, sizes, input protocol,
 * vertices, faces, pools, block starts): what files saved for one cell
 * record, so that another sequence's are refused (datasets/fingerprint.c). */
uint64_t tcb_sequence_fingerprint(const tcb_sequence *s);

/* Frames start .. start + n_frames - 1 of `from` (raw: before any
 * normalization or pools) as a new sequence named `name`, all in one of
 * from's blocks (an error naming the block otherwise); the copy has no
 * blocks, pools or normalization yet (tcb_sequence_prepare). */
int tcb_sequence_cut(const tcb_sequence *from, int start, int n_frames, const char *name, tcb_sequence *out,
                     tcb_error *err);

/* A clip folder as DynoSurf, PDG and Neu-PiG distribute theirs: the GT
 * meshes <dir>/gt/NNNN.obj (of one topology, ordered by number) and, when
 * <dir>/pcl_seqs exists, one <dir>/pcl_seqs/NNNN.npy per mesh, each an
 * (N, 3) float array of the same N (the tracked points). Raw, like
 * tcb_sequence_read_objdir; errors name the file (datasets/clipdir.c). */
int tcb_sequence_read_clipdir(const char *dir, const char *name, tcb_sequence *out, tcb_error *err);
/* One pcl_seqs frame parsed from buf[0..len): an (n, 3) float array of
 * finite values into *pts (malloc'ed [n][3]); n must be want when want > 0.
 * Errors say what is wrong, without a file name (the fuzz target's entry). */
int tcb_track_frame_parse(const void *buf, size_t len, int want, float **pts, int *n, tcb_error *err);

/* Occupancy Flow's point-cloud sequence <dir>/pcl_seq/NNNNNNNN.npz
 * (points float16, loc, scale; frames numbered without gaps) in world
 * coordinates (loc + scale·points): a sequence without faces (n_faces 0)
 * of `keep` of its points (0: all), the same in every frame, chosen by the
 * stream "pcl_seq/<name>" (datasets/pcl_seq.c). */
int tcb_sequence_read_pcl_seq(const char *dir, const char *name, int keep, tcb_sequence *out, tcb_error *err);
/* Its frame count and the vertices a sequence keeps, reading one frame:
 * what a dry run needs. */
int tcb_sequence_probe_pcl_seq(const char *dir, int keep, int *n_frames, int *n_verts, tcb_error *err);
/* One such frame: its N points in world coordinates into *world
 * (malloc'ed [N][3]); N must be want when want > 0. Errors name the file. */
int tcb_pcl_seq_frame_read(const char *path, int want, float **world, int *n, tcb_error *err);

/* Write every frame as <dir>/mesh_NNNN.obj (atomically, one file each). */
int tcb_sequence_write_objdir(const tcb_sequence *s, const char *dir, tcb_error *err);

void tcb_sequence_free(tcb_sequence *s);

/* ---- Loading with a binary cache ------------------------------------- */

typedef struct tcb_load_opts {
    tcb_normalization norm;
    int pool_size;         /* TCB_DEFAULT_POOL_SIZE */
    uint64_t pool_seed;    /* also seeds the alignment's samples */
    const char *cache_dir; /* NULL: no cache */
    int align_samples;     /* > 0: rotation alignment (tcb/align.h) on that many
                            * points per frame; 0: none */
    const tcb_reporter *reporter; /* told of a cache entry refused; NULL: silent */
} tcb_load_opts;

/* What every loader does after reading raw frames: normalize, align the
 * yaw when o->align_samples > 0, sample the pools (o->pool_size, 0 for the
 * default). */
int tcb_sequence_prepare(tcb_sequence *s, const tcb_load_opts *o, tcb_error *err);

/* Read an OBJ directory, normalize and sample pools; with a cache_dir the
 * result is stored as HDF5 and later loads skip parsing. A cache entry is
 * reused only when its recorded source (file names, sizes, mtimes), options
 * and format version all match and its arrays have their recorded
 * checksum; any other is rebuilt, and said to opts->reporter. */
int tcb_sequence_load_objdir(const char *dir, const char *name, const tcb_load_opts *opts,
                             tcb_sequence *out, tcb_error *err);

/* The HDF5 cache file itself (also usable as an exchange format). `key` is an
 * opaque string that must match on load; a mismatch returns TCB_ERR_UNSUPPORTED
 * ("stale") so the caller re-parses. Arrays whose checksum differs from the
 * one saved with them (a flipped bit HDF5 does not see) are TCB_ERR_INPUT. */
int tcb_sequence_cache_save(const char *path, const tcb_sequence *s, const char *key,
                            tcb_error *err);
int tcb_sequence_cache_load(const char *path, const char *key, tcb_sequence *out,
                            tcb_error *err);

#ifdef __cplusplus
}
#endif
#endif
