/* The ops a pcgrid method (Neu-PiG, PDG) shares with the others: what
 * turns a trainer of a template carried into every frame into a
 * tcb_method_ops — the inputs drawn and the template built the same way
 * by fit, load and the calibration, the fit loop with its checkpoints, the
 * model file, the read-out of the fitted frames, train_steps and the
 * "template" unit. A method keeps only what is its own: its params and
 * presets, its trainer behind tcb_pcgrid_hooks, its cost estimate.
 *
 * As SQLite's virtual tables do, a method's object starts with a
 * tcb_pcgrid_method (its first member), so that the shared ops take the
 * method's `self` as it is:
 *
 *     typedef struct neupig_method { tcb_pcgrid_method base; tcb_neupig_arch arch; ... } neupig_method;
 *     const tcb_method_ops tcb_method_neupig = {..., .create = create, .estimate = estimate,
 *                                               TCB_PCGRID_SHARED_OPS};
 *
 * The method's object holds nothing on the heap beyond the base: destroy
 * frees the base's and the object. */
#ifndef TCB_PCGRID_METHOD_H
#define TCB_PCGRID_METHOD_H

#include <stddef.h>
#include <stdint.h>

#include "methods/pcgrid/fitted.h"
#include "methods/pcgrid/template.h"
#include "tcb/json.h"
#include "tcb/method.h"

/* What the method's problem is built from: every frame's cloud in the
 * method's frame (the cube, or the method's map), the map, the keyframe
 * and the template as it starts (NULL for a method whose trainer makes
 * its template: hooks->trained_template). */
typedef struct tcb_pcgrid_inputs {
    tcb_pcgrid_clouds clouds;
    const tcb_pcgrid_frame_map *map;
    int key;
    const tcb_mesh *template_mesh;
    void *problem;               /* hooks->problem_size bytes, the method's */
} tcb_pcgrid_inputs;

/* A method's own part. `self` is the method's object; `trainer` points to
 * hooks->trainer_size zeroed bytes before trainer_init. */
typedef struct tcb_pcgrid_hooks {
    const char *name;            /* messages, the bar, the stream "<name>/points" */
    const char *magic;           /* the model file's 8 bytes */
    size_t problem_size, trainer_size;
    /* The method's problem over in (in->problem, zeroed), from seq too (its
     * normals, say); problem_free releases what it allocated, also after a
     * failed init. */
    int (*problem_init)(void *self, const tcb_sequence *seq, tcb_pcgrid_inputs *in, tcb_error *err);
    void (*problem_free)(void *problem);
    int (*trainer_init)(void *trainer, const void *self, const void *problem, uint64_t seed, tcb_error *err);
    void (*trainer_free)(void *trainer);
    /* One epoch; epochs done; the whole training state (neural/train_loop.h). */
    int (*step)(void *trainer, double *loss, tcb_error *err);
    long long (*done)(const void *trainer);
    int (*save)(const void *trainer, uint64_t seed, double seconds, const char *path, tcb_error *err);
    int (*load)(void *trainer, uint64_t seed, const char *path, double *seconds, tcb_error *err);
    /* The trainer's parameters (what the model file holds), *n of them. */
    float *(*params)(void *trainer, size_t *n);
    /* X [frames][nv][3]: the template carried into every frame by the
     * trainer's current parameters. */
    int (*frames)(void *trainer, float *X, tcb_error *err);
    /* The sizes the model file's parameters were fitted with. */
    cJSON *(*manifest)(const void *self, size_t n_params);
    /* Optional (NULL: none). Puts a fresh trainer of train_steps into the
     * phase that dominates a fit (tcb/method.h, train_steps): PDG's first
     * 101 epochs train the input term alone, cheaper than the rest. */
    void (*main_phase)(void *trainer);
    /* Optional (NULL: the pcgrid cube, prepare.h). The map of the drawn
     * clouds into the method's frame. */
    tcb_pcgrid_map_fn frame_map;
    /* Optional (NULL: the occupancy rule, prepare.h). The keyframe of the
     * mapped clouds. */
    int (*keyframe)(const float *const *clouds, const int *n, int T, int *key, tcb_error *err);
    /* Optional (NULL: the keyframe's Poisson template, built before the
     * first step from b->spec). A method whose trainer makes its template
     * (DynoSurf extracts it after its stage 1): no template is built, and
     * after training this copies the trainer's into *out, the mesh the
     * read-out carries. */
    int (*trained_template)(void *trainer, tcb_mesh *out, tcb_error *err);
    /* Optional (NULL: nothing). One line on the problem a fit is about to
     * train (its sizes), which fit logs at info level. */
    void (*describe)(const void *problem, char *line, size_t size);
    /* Optional (NULL: "template" is the method's one unit). One run of
     * the method's unit past "template" (its ops' units[unit], unit >= 1)
     * on train_steps' trainer, which the next train_steps call puts back
     * into its main phase. */
    int (*run_unit)(void *trainer, int unit, tcb_error *err);
} tcb_pcgrid_hooks;

enum { TCB_PCGRID_NORMALS_ESTIMATED, TCB_PCGRID_NORMALS_GT, TCB_PCGRID_NORMALS_INPUT };

struct tcb_pcgrid_steps;

typedef struct tcb_pcgrid_method {
    const tcb_pcgrid_hooks *hooks;
    /* Settings (the method's parse). spec's gt_normals and seed are set
     * per sequence and fit. */
    int points, keyframe_res, recon_points;
    int normals;                 /* TCB_PCGRID_NORMALS_* */
    tcb_pcgrid_template_spec spec;
    long long epochs, checkpoint_every;
    /* The fitted model (after fit or load). */
    uint64_t seed;
    float *params;               /* [n_params], for save */
    size_t n_params;
    tcb_pcgrid_fitted fitted;
    struct tcb_pcgrid_steps *steps; /* train_steps' training; NULL: none */
} tcb_pcgrid_method;

/* The params every pcgrid method takes, into b: "normals" (input, the
 * default: what the sequence's input comes with | estimated | gt),
 * "recon_points" (2 500), "checkpoint_every" (50). */
#define TCB_PCGRID_RECON_POINTS 2500
int tcb_pcgrid_parse_common(const cJSON *j, const char *where, tcb_pcgrid_method *b, tcb_error *err);

/* The shared entries of tcb_method_ops (tcb/method.h). */
int tcb_pcgrid_fit(void *self, const tcb_sequence *seq, const tcb_fit_ctx *ctx, tcb_error *err);
int tcb_pcgrid_transfer_op(void *self, const tcb_sequence *seq, int i, int j, const float *src, int n, float *out,
                           tcb_rng *rng, tcb_error *err);
int tcb_pcgrid_reconstruct_op(void *self, const tcb_sequence *seq, int i, int j, int frame, tcb_rng *rng,
                              float **pts, int *n, tcb_error *err);
int tcb_pcgrid_surface_op(void *self, const tcb_sequence *seq, int frame, tcb_rng *rng, tcb_uv_mesh *out,
                          tcb_error *err);
int tcb_pcgrid_save(void *self, const char *path, tcb_error *err);
int tcb_pcgrid_load(void *self, const tcb_sequence *seq, const char *path, tcb_error *err);
void tcb_pcgrid_destroy(void *self);
int tcb_pcgrid_train_steps(void *self, const tcb_sequence *seq, const tcb_fit_ctx *ctx, long long n,
                           tcb_error *err);
/* train_steps' training once the first call started it, else NULL: the
 * inputs it trains on (every frame's cloud in the cube, the keyframe, the
 * template as it started, the method's problem) and, unless trainer is
 * NULL, its trainer's state (hooks->trainer_size bytes, the method's).
 * For bench_train_step, which hands a PyTorch peer the same data. */
const tcb_pcgrid_inputs *tcb_pcgrid_steps_inputs(const void *self, const void **trainer);
int tcb_pcgrid_run_unit(void *self, const tcb_sequence *seq, const tcb_fit_ctx *ctx, int unit, tcb_error *err);
const char *tcb_pcgrid_normals_used(void *self, const tcb_sequence *seq);
/* Whether b's normals on seq are GT's: its "normals" param, or under
 * "input" the sequence's input normals. */
int tcb_pcgrid_uses_gt_normals(const tcb_pcgrid_method *b, const tcb_sequence *seq);
extern const char *const tcb_pcgrid_units[]; /* {"template", NULL} */

/* Those entries, for a method's ops table. */
#define TCB_PCGRID_SHARED_OPS                                                                                     \
    .fit = tcb_pcgrid_fit, .transfer = tcb_pcgrid_transfer_op, .reconstruct = tcb_pcgrid_reconstruct_op,         \
    .save = tcb_pcgrid_save, .load = tcb_pcgrid_load, .destroy = tcb_pcgrid_destroy,                             \
    .surface = tcb_pcgrid_surface_op, .train_steps = tcb_pcgrid_train_steps, .units = tcb_pcgrid_units,           \
    .run_unit = tcb_pcgrid_run_unit, .normals = tcb_pcgrid_normals_used

/* The estimate of a fit: b->epochs epochs (each over every frame) priced
 * by the step of calibrated preset k of `presets` (-1: none matches the
 * sizes), after the template, which a fit builds once. */
void tcb_pcgrid_estimate(const tcb_pcgrid_method *b, const char *const *presets, int k, tcb_cost_estimate *out);

#endif
