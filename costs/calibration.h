/* Measured costs: what `tcbench calibrate` measures on the machine it runs
 * on, and what `tcbench run --dry-run` prices cells with (docs/cluster.md,
 * "Sizing an allocation").
 *
 * A calibration file holds, for the machine it names, the seconds of
 *   - one training step of each trained method at each preset (kind step),
 *   - the method's part of an evaluation pair: the transfer of frame i's
 *     vertices and the reconstruction of both frames with their Chamfer
 *     distances (kind eval_pair),
 *   - one of a method's named units (kind unit: a registration, a template
 *     mesh; tcb_method_ops.units) at each preset,
 *   - the reconstruction metrics of one frame of a method with a surface:
 *     the method's surface of the frame (kind surface_mesh), and the
 *     harness's part, both sample sets and the metrics, at `size` samples
 *     per mesh (kind surface_frame),
 *   - the harness's scoring of a pair: projection, metrics, geodesic error
 *     (kind score_pair, no method),
 * each at the thread counts measured, on the calibration sequence
 * (tcb_calibration_sequence), whose vertex and frame counts it records.
 * A unit may also be measured on a sequence of a config (`tcbench calibrate
 * CONFIG`): such a cost names the sequence and its vertex count, and prices
 * that sequence's cells only, over the calibration sequence's (a unit's
 * cost is the shape's as much as its vertex count's: docs/cluster.md).
 *
 * The face of costs/ for the dry run (harness/plan.c) and the command line:
 * the file, the set a dry run reads, and pricing. Measuring is
 * costs/step_timing.h, the command costs/calibrate.h. */
#ifndef TCB_COSTS_CALIBRATION_H
#define TCB_COSTS_CALIBRATION_H

#include "tcb/method.h"

typedef enum tcb_cost_kind {
    TCB_COST_STEP,
    TCB_COST_EVAL_PAIR,
    TCB_COST_SCORE_PAIR,
    TCB_COST_UNIT,
    TCB_COST_SURFACE_FRAME,
    TCB_COST_SURFACE_MESH,
    TCB_COST_KINDS
} tcb_cost_kind;

/* The calibration sequence's frames (tcb_calibration_sequence). */
#define TCB_CALIBRATION_FRAMES 6
/* A config's sequence a unit was measured on: "dataset/sequence". */
#define TCB_COST_SEQUENCE_MAX 200

typedef struct tcb_cost_entry {
    tcb_cost_kind kind;
    char method[64], preset[32]; /* "" for score_pair */
    int threads;
    int samples;                 /* steps or pairs timed */
    double seconds;              /* mean per step, pair, unit or frame */
    char unit[32];               /* kind unit: its name; else "" */
    int size;                    /* kind surface_frame: samples per mesh; else 0 */
    /* kind unit: the config's sequence it was measured on, its vertex
     * count; "" and 0: the calibration sequence */
    char sequence[TCB_COST_SEQUENCE_MAX];
    int vertices;
} tcb_cost_entry;

typedef struct tcb_calibration {
    char origin[4096];    /* the file it was read from, or "built-in" */
    char machine[160];    /* "CPU model, N cores": names it in the dry run's bases */
    char *machine_json;   /* the whole description (CPU, cores, library versions), as JSON text */
    int n_verts;          /* the calibration sequence's: the pairs' costs were measured at it */
    int n_frames;         /* and its frames (an epoch's steps were measured over them) */
    tcb_cost_entry *entries;
    int n, cap;
} tcb_calibration;

void tcb_calibration_free(tcb_calibration *c);
int tcb_calibration_add(tcb_calibration *c, const tcb_cost_entry *e, tcb_error *err);
int tcb_calibration_parse(const char *text, const char *origin, tcb_calibration *out, tcb_error *err);
int tcb_calibration_write(const tcb_calibration *c, const char *path, tcb_error *err);

/* The committed defaults (calibration/default.json, compiled in). */
int tcb_calibration_builtin(tcb_calibration *out, tcb_error *err);

/* Where `calibrate` writes and the dry run reads a user's calibration:
 * $XDG_CONFIG_HOME/tcbench/calibration.json, else
 * $HOME/.config/tcbench/calibration.json; "" when neither is set. */
void tcb_calibration_user_path(char *out, size_t size);

/* The calibrations a dry run of run_dir reads, first match wins: the run
 * directory's calibration.json (one made on the nodes that run it), the
 * user's, the built-in defaults. A file that exists but does not parse is
 * an error naming it. */
#define TCB_CALIBRATION_SOURCES 3
typedef struct tcb_calibration_set {
    tcb_calibration c[TCB_CALIBRATION_SOURCES];
    int n;
} tcb_calibration_set;
int tcb_calibration_set_load(const char *run_dir, tcb_calibration_set *s, tcb_error *err);
void tcb_calibration_set_free(tcb_calibration_set *s);

/* The cost at `threads` from the first calibration that measured key on
 * key->sequence, else from the first that measured it on the calibration
 * sequence (a surface frame's per sample of a mesh): the measured value,
 * else interpolated log-linearly in the thread count between the nearest measured counts, else extrapolated
 * with the scaling of the last two (at best linear, never slower with more
 * threads; constant from a single count). */
typedef struct tcb_cost_price {
    double seconds;
    const tcb_calibration *from;
    int vertices;       /* of the sequence it was measured on */
    int on_sequence;    /* the key's sequence's own cost (else the calibration sequence's) */
    int lo, hi;         /* the measured thread counts it derives from */
    int extrapolated;   /* threads outside [lo, hi] */
} tcb_cost_price;
typedef struct tcb_cost_key {
    tcb_cost_kind kind;
    const char *method, *preset, *unit; /* "" where the kind has none */
    const char *sequence;               /* a unit's or the scoring's on this sequence first; NULL or "": only
                                         * the calibration sequence's */
} tcb_cost_key;
int tcb_cost_lookup(const tcb_calibration_set *s, const tcb_cost_key *key, int threads, tcb_cost_price *out);

/* Prices a cell's estimate: one that named a preset with steps
 * (abi_version >= 5) gets fit_s = steps x the step cost (x the frames over
 * the calibration sequence's with step_frames) and eval_s from the pair
 * costs, scaled with the vertex count's ratio (a pair carries every
 * vertex); its unit uses (abi_version >= 6) are added at their counts,
 * each from its cost measured on `sequence` (the cell's "dataset/sequence")
 * where a calibration has one, else the calibration sequence's, scaled
 * with the vertex count's ratio to the measured sequence's to its
 * exponent; a method with a surface (surface_samples > 0: the
 * config's samples per mesh) gets the reconstruction metrics of the frames
 * its pairs use added, or, not measured, a basis that says so; every
 * estimate with an eval_s gets the harness's scoring of q->n_pairs pairs
 * added, scaled with the square of the vertex count (the metrics compare
 * vertex with vertex; an upper bound). Unknown parts make fit_s and eval_s
 * -1, and basis says which command measures them. */
void tcb_cost_price_cell(const tcb_calibration_set *s, const char *method, const char *sequence,
                         const tcb_cost_query *q, int surface_samples, tcb_cost_estimate *e);

#endif
