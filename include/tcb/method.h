/* tcbench — the method interface.
 *
 * A method is a versioned table of function pointers, in the manner of
 * SQLite's sqlite3_module: the harness never knows a method by name, only
 * through this table. The harness owns data loading, the evaluation pairs,
 * metrics and all I/O; a method owns only its model.
 *
 * Lifecycle for one (dataset, sequence, method, seed) cell:
 *     create(params_json) → [load(checkpoint) | fit(seq)] → prepare_pairs
 *     (optional) → transfer(i, j, …) × n_pairs → reconstruct(…) × 2 n_pairs
 *     (optional) → destroy
 *
 * Rules:
 *  - Return TCB_OK or an error code with a one-line message in *err.
 *    Never print, never exit(); use ctx->reporter for progress and logs.
 *  - Methods are unsupervised: they may read the sequence's vertices, faces
 *    and point pools, but must not use the fact that vertex ids correspond
 *    across frames (only the `oracle` sanity row does, by design).
 *  - All randomness comes from the seed in tcb_fit_ctx or the rng passed to
 *    transfer/reconstruct: the same seed and thread count give the same bits.
 *
 * Out-of-tree plug-ins: a shared object that exports
 *     const tcb_method_ops *const *tcb_plugin_methods(int *count);
 * returning `count` tables with abi_version TCB_METHOD_ABI_OLDEST to
 * TCB_METHOD_ABI_VERSION,
 * loaded with `tcbench --plugin path/to/lib.so …` or the config key
 * "plugins". See docs/adding-a-method.md. */
#ifndef TCB_METHOD_H
#define TCB_METHOD_H

#include <stdint.h>
#include <stdlib.h>

#include "tcb/error.h"
#include "tcb/progress.h"
#include "tcb/rng.h"
#include "tcb/sequence.h"

#ifdef __cplusplus
extern "C" {
#endif

/* 2 added `estimate`, 3 `surface`, 4 `prepare_pairs` and the reconstruct
 * that declines (TCB_ERR_UNSUPPORTED), 5 `presets`, `train_steps` and the
 * estimate priced by calibrated costs (tcb_cost_estimate.steps, .preset),
 * 6 `units`, `run_unit`, the estimate's unit counts (.units, .n_units) and
 * steps that grow with the frame count (.step_frames), 7 `version`, 8
 * `normals` and the sequence's input normals (tcb_sequence.input_normals),
 * 9 eight unit counts in the estimate (TCB_MAX_UNIT_USES, four before);
 * tables of older versions still load, and the harness reads no member
 * their version did not have (their tables end before it; the estimate it
 * zeroes, and an older table fills at most its version's unit slots). */
#define TCB_METHOD_ABI_VERSION 9
#define TCB_METHOD_ABI_OLDEST 1

typedef struct tcb_fit_ctx {
    uint64_t seed;          /* the cell's seed */
    int n_threads;          /* threads the method may use */
    const char *work_dir;   /* per-cell directory for checkpoints; exists. A fit may
                             * keep its training state there to resume a killed
                             * run; --force empties it first */
    tcb_reporter reporter;  /* progress bar and log */
    double *resumed_fit_s;  /* out, may be NULL: a fit that continues a killed
                             * one's training state from work_dir sets it to the
                             * seconds that state cost the earlier processes, so
                             * the cell's fit_s counts the whole fit. Appended
                             * last: tables built before it ignore it */
    /* May be NULL. Nonzero once the process was asked to stop (SIGTERM,
     * SIGUSR1): a long fit saves its state in work_dir at the next safe
     * point and returns TCB_ERR_INTERRUPTED; the next run resumes it. A fit
     * that ignores it is killed with the process. Appended last, as above. */
    int (*interrupted)(const void *arg);
    const void *interrupt_arg;
} tcb_fit_ctx;

static inline int tcb_fit_interrupted(const tcb_fit_ctx *ctx)
{
    return ctx->interrupted && ctx->interrupted(ctx->interrupt_arg);
}

/* What `tcbench run --dry-run` knows of a cell before running it. */
typedef struct tcb_cost_query {
    int n_frames, n_verts;  /* the sequence's; 0 when its data are absent */
    int n_pairs;            /* evaluation pairs */
    int n_threads;          /* threads of the cell */
} tcb_cost_query;

/* Seconds of wall time on the machine the method's costs were measured on
 * (say which in `basis`); negative: unknown (for example a cost that grows
 * with the vertex count when the data are absent).
 *
 * From abi_version 5 a trained method may leave the pricing to the
 * harness: it names the preset (one of its `presets`) whose costs
 * `tcbench calibrate` measured and the training steps a fit takes, and the
 * harness sets fit_s, eval_s and basis from the calibration of (method,
 * preset, the cell's threads). The harness clears both before the call;
 * a method whose configuration no preset prices leaves preset empty and
 * says why in basis, with fit_s and eval_s negative. */
typedef struct tcb_unit_use {
    char unit[32];          /* one of the method's `units` */
    double fit, eval;       /* how many a fit and a cell's evaluation run */
    double exponent;        /* a unit costs (vertices / the calibration sequence's)^exponent
                             * times what calibrate measured */
    int threads;            /* the threads each runs with: 0 the cell's (priced at the
                             * cell's count), 1 one (a method running units side by side
                             * divides its counts by its threads itself) */
} tcb_unit_use;

/* Unit counts an estimate holds: 8 from abi_version 9, 4 before (a
 * table of an older version never fills more). */
#define TCB_MAX_UNIT_USES 8

typedef struct tcb_cost_estimate {
    double fit_s, eval_s;
    char basis[200];        /* "40 000 steps x 63.5 ms (bench_train_step, 1 thread)" */
    long long steps;        /* abi_version >= 5: training steps of a fit */
    char preset[32];        /* abi_version >= 5: the calibrated preset pricing them; "" none */
    /* abi_version >= 6. A step's cost grows with the frame count (an epoch
     * over every frame): priced x q->n_frames / the calibration sequence's. */
    int step_frames;
    /* abi_version >= 6: the method's measured units a cell runs (of
     * `preset`, or of "" for a method without presets), added by the
     * harness to fit_s and eval_s, which the method leaves at what the
     * units do not cover (0 when they cover everything). */
    int n_units;
    tcb_unit_use units[TCB_MAX_UNIT_USES];
} tcb_cost_estimate;

/* A method's surface of one frame as a triangle mesh (`surface` below),
 * parametrised by charts or not.
 *
 * With charts (n_charts >= 1; the atlas family): each vertex lies in one
 * chart at (u, v) in [0,1]^2; the harness places chart c's unit square in
 * cell c of one texture shared by every chart and frame, so the method
 * never knows the texture and the same (chart, u, v) is the same texel in
 * every frame: a chart that slides over the body shows it.
 *
 * Without (n_charts 0, uv and chart NULL; a template moved into every
 * frame, as neupig's): a vertex is its own mark, as it is the same point
 * of the template in every frame; `tcbench frames` colours each vertex by
 * its position in the first frame it draws, so a template that slides over
 * the body shows it too. The reconstruction metrics use only verts and
 * faces, with charts or without. */
typedef struct tcb_uv_mesh {
    int n_verts, n_faces, n_charts;
    float *verts;    /* [n_verts][3] normalized coordinates, like transfer's */
    float *uv;       /* [n_verts][2] in [0,1]^2 of the vertex's chart; NULL without charts */
    int32_t *chart;  /* [n_verts] in [0, n_charts); NULL without charts */
    int32_t *faces;  /* [n_faces][3] vertex ids; with charts counter-clockwise
                      * in (u, v), a face's three vertices in one chart */
} tcb_uv_mesh;

/* Frees what a method's `surface` malloc'ed and zeroes *m. */
static inline void tcb_uv_mesh_free(tcb_uv_mesh *m)
{
    free(m->verts), free(m->uv), free(m->chart), free(m->faces);
    const tcb_uv_mesh none = {0, 0, 0, NULL, NULL, NULL, NULL};
    *m = none;
}

typedef struct tcb_method_ops {
    int abi_version;            /* TCB_METHOD_ABI_VERSION */
    const char *name;           /* unique, [a-z0-9_]+ */
    const char *description;    /* one line for `tcbench methods` */

    /* Parse params (a JSON object as text, "{}" for defaults); unknown keys
     * and bad values are TCB_ERR_INPUT naming the key. */
    int (*create)(const char *params_json, void **self, tcb_error *err);

    /* Train or precompute on the whole sequence (one model per sequence). */
    int (*fit)(void *self, const tcb_sequence *seq, const tcb_fit_ctx *ctx, tcb_error *err);

    /* Map n points src (the GT vertices of frame i, [n][3]) to points on
     * frame j, out [n][3]. The harness then projects out onto frame j's GT
     * vertices. rng is the pair's stream (fresh input clouds etc.). */
    int (*transfer)(void *self, const tcb_sequence *seq, int i, int j, const float *src,
                    int n, float *out, tcb_rng *rng, tcb_error *err);

    /* Optional (NULL: no reconstruction, "-" in CD columns). Surface samples
     * of `frame` (i or j) in the context of pair (i, j), as evaluated after
     * transfer(i, j); *pts is malloc'ed [*n][3] and freed by the caller.
     * From abi_version 4 it may return TCB_ERR_UNSUPPORTED (*pts NULL): this
     * configured method has no reconstruction of the pair, whose CD is then
     * "-"; decline for every pair of a cell or for none (a method whose
     * params choose whether it reconstructs). */
    int (*reconstruct)(void *self, const tcb_sequence *seq, int i, int j, int frame,
                       tcb_rng *rng, float **pts, int *n, tcb_error *err);

    /* Optional checkpointing of a fitted model (NULL: refit on resume). */
    int (*save)(void *self, const char *path, tcb_error *err);
    int (*load)(void *self, const tcb_sequence *seq, const char *path, tcb_error *err);

    void (*destroy)(void *self);

    /* Optional (NULL: "no estimate"; read only from tables of abi_version
     * >= 2). The compute a cell of this configured method will take, from
     * the method's known step costs; called on a created, unfitted self. */
    void (*estimate)(void *self, const tcb_cost_query *q, tcb_cost_estimate *out);

    /* Optional (NULL: no textured pictures; read only from tables of
     * abi_version >= 3). The fitted model's surface of `frame` alone (not in
     * a pair's context), every array malloc'ed and freed by the caller with
     * tcb_uv_mesh_free. rng is a stream of the frame's own (fresh input
     * clouds, drawn as the evaluation draws them). The topology (n_verts,
     * n_faces, faces, chart, uv) must be the same for every frame of a
     * sequence: only verts move, so one texture and one camera serve all. */
    int (*surface)(void *self, const tcb_sequence *seq, int frame, tcb_rng *rng, tcb_uv_mesh *out,
                   tcb_error *err);

    /* Optional (NULL: none; read only from tables of abi_version >= 4). The
     * pairs the harness is about to transfer, told before the first of
     * them, for a method that computes them in one batch (the external one
     * runs a process for all of them at once): pair m, numbered first + m,
     * maps frame pairs[2m] to pairs[2m + 1], m < n. The number is the pair's
     * index in the split in an evaluation and in inspect (the cell's pairs,
     * or its one); `tcbench frames` numbers its own pairs from 0. transfer
     * (and reconstruct) then follow for exactly these pairs, in this order.
     * ctx is the fit's (seed, threads, work_dir, reporter, stop request;
     * resumed_fit_s NULL); a stop request may end it with
     * TCB_ERR_INTERRUPTED, which keeps the fitted model. Its time counts in
     * the cell's eval_s. */
    int (*prepare_pairs)(void *self, const tcb_sequence *seq, const int *pairs, int first, int n,
                         const tcb_fit_ctx *ctx, tcb_error *err);

    /* Optional (NULL: none; read only from tables of abi_version >= 5).
     * The configurations `tcbench calibrate` measures, NULL-terminated: a
     * method created with params {"preset": NAME} for each NAME, whose
     * estimate then names the preset that prices it. */
    const char *const *presets;

    /* Optional (NULL: not calibrated; abi_version >= 5). For `tcbench
     * calibrate` and bench_train_step: the first call starts a training of
     * this created, unfitted method on seq (ctx's seed; the caller has set
     * the OpenMP thread count to ctx->n_threads), every call runs n more
     * steps of it (the steps a fit's step count counts, in the phase that
     * dominates the fit); the caller times the calls. Afterwards the method
     * is fitted with the weights of the steps done, so that transfer and
     * reconstruct can be timed on seq too. */
    int (*train_steps)(void *self, const tcb_sequence *seq, const tcb_fit_ctx *ctx, long long n, tcb_error *err);

    /* Optional (NULL: none; read only from tables of abi_version >= 6).
     * Named costs besides the training step that `tcbench calibrate`
     * measures, NULL-terminated ("register_random": one registration
     * between the frames of a random pair), at each preset (a method
     * without presets: created with "{}", preset "") and thread count; the
     * estimate counts them (tcb_cost_estimate.units). run_unit runs one of
     * units[unit] on seq, on a created method (fitted or not: it prepares
     * what it needs, and the caller runs it once untimed first) with the
     * caller's OpenMP thread count; the caller times the calls. */
    const char *const *units;
    int (*run_unit)(void *self, const tcb_sequence *seq, const tcb_fit_ctx *ctx, int unit, tcb_error *err);

    /* Optional (NULL: none; read only from tables of abi_version >= 7). The
     * method's own version ("1.2", a commit), recorded with a plug-in's
     * file digest in every cell it computes, so that a result can be
     * traced to the code that made it. A built-in method's is tcbench's
     * (the cell's git_revision). */
    const char *version;

    /* Optional (NULL: the method takes points only; read only from tables
     * of abi_version >= 8). The normals a created method uses with its
     * input points on seq: "gt", "estimated" (from the sequence's input
     * normals, tcb_sequence.input_normals, or estimated by the method
     * itself when the sequence gives none), "" none; a static string.
     * Recorded in the cell, so a table says which methods had normals. */
    const char *(*normals)(void *self, const tcb_sequence *seq);
} tcb_method_ops;

/* The method's version string (tcb_method_ops.version); "" when none. */
static inline const char *tcb_method_version(const tcb_method_ops *ops)
{
    return ops->abi_version >= 7 && ops->version ? ops->version : "";
}

/* The normals the method uses on seq (tcb_method_ops.normals); "" none. */
static inline const char *tcb_method_normals(const tcb_method_ops *ops, void *self, const tcb_sequence *seq)
{
    const char *n = ops->abi_version >= 8 && ops->normals ? ops->normals(self, seq) : NULL;
    return n ? n : "";
}

/* The method of ops gives a surface per frame (tcb_method_ops.surface). */
static inline int tcb_method_has_surface(const tcb_method_ops *ops)
{
    return ops->abi_version >= 3 && ops->surface;
}

typedef const tcb_method_ops *const *(*tcb_plugin_entry_fn)(int *count);
#define TCB_PLUGIN_ENTRY "tcb_plugin_methods"

#ifdef __cplusplus
}
#endif
#endif
