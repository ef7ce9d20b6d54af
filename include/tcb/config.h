/* tcbench — run configuration (JSON, validated; errors name the key).
 *
 * Paths to code resolve against the config file's directory (made
 * absolute when the config is read, config/config_paths.c): "plugins",
 * and an external method's "command" elements that name a file beside the
 * config. Paths to data and results — "output", "splits_dir", "cache_dir",
 * a dataset's "root" — stay relative to the current directory (the
 * shipped configs are run from the repository root: "output":
 * "runs/quick"), as do --out, --root and --plugin on the command line.
 *
 *   { "name": "quick",
 *     "output": "runs/quick",            run directory (relative to the CWD)
 *     "splits_dir": "splits",            where split files live (written once; CWD)
 *     "cache_dir": ".tcbench-cache",     parsed-sequence cache ("" disables; CWD)
 *     "plugins": ["path/lib.so"],        optional out-of-tree methods (relative to
 *                                        the config file's directory)
 *     "seeds": [0],
 *     "threads": 2,
 *     "reference": { "source": "iccv21", "tables": ["5"] },   the paper's tables
 *                                        this config reproduces (tcbench report --reference)
 *     "variants": { "cpu": { "seeds": [0], "params": { "mca": { "preset": "cpu" } } },
 *                   "paper": { … } },    chosen with --variant (default: the first);
 *                                        "params" merge into the methods with that label
 *                                        or method name; the run goes to <output>/<variant>
 *     "evaluation": { "pairs": 500, "split_seed": 2021, "pool_size": 10000,
 *                     "pool_seed": 0, "input_points": 2500,
 *                     "protocol": "pairs" | "clips" | ["pairs", "clips"],   the paper's
 *                                        pairs (default), the 17-frame clips of DynoSurf/PDG/
 *                                        Neu-PiG (Corr; docs/protocol.md), or both
 *                     "clips": 10,       clips per sequence (clip protocol only)
 *                     "fit": "sequence" | "per_clip",   one fit per sequence (default), or
 *                                        each clip fitted as a sequence of its own, in its own
 *                                        frame (the 2024-2026 papers; clip protocol only)
 *                     "input_normals": "none" | "gt" | "estimated",   normals with the
 *                                        input clouds, for methods that take them
 *                     "recon_frame": "sequence" | "frame_box",   the frame of the
 *                                        reconstruction metrics: the sequence's normalized
 *                                        one, or each frame's GT box (Neu-PiG's evaluation)
 *                     "surface_samples": 100000 },   samples per mesh of the
 *                                        reconstruction metrics (CD-L2, NC, F-score)
 *                                        of the methods that give surfaces
 *     "datasets": [
 *       { "name": "synth", "source": "synthetic", "seed": 0, "frames": 0,
 *         "normalization": "first_frame" | "none" | "per_frame" | "clip_bbox" | "first_frame_diag",
 *         "align_rotation": false,       yaw-align each frame to the previous (AMA; tcb/align.h)
 *         "align_samples": 1000,         vertices the alignment's Chamfer runs on
 *         "sampling": "without_replacement" | "with_replacement",
 *         "optional": false,             skip (with a message) when root is absent
 *         "root": "../shared/data/anim", objdir sources only: <root>/<sequence>/ (CWD); may be
 *                                        left out and given as --root NAME=DIR or in the
 *                                        environment as TCBENCH_ROOT_<NAME>
 *         "sequences": [ { "name": "quadruped_walk", "role": "validation" } ] },
 *         under "fit": "per_clip" a sequence entry may list its clips' first frames:
 *           { "name": "crane", "role": "validation", "clip_starts": [10, 27] }
 *         which stands for the sequences crane_0010 and crane_0027, each written
 *           { "name": "crane_0010", "role": "validation", "clip_of": "crane", "start": 10 };
 *         an entry without either is one clip itself (exactly 17 frames)
 *       { "name": "dfaust", "source": "dfaust", tcb/dfaust.h: one block of frames per subject
 *         "root": "../shared/data/dfaust", holds registrations_m.hdf5 and/or _f.hdf5
 *         "subjects": ["50002", "50004"],  default: every subject that has the sequence
 *         "normalization": "none",         this source's default, as
 *         "sampling": "with_replacement",  this one's (reference-protocol §1.2, §1.3)
 *         "optional": false,               as objdir; no "align_rotation" (it would chain
 *                                          frames across subjects)
 *         "sequences": [ { "name": "jumping_jacks", "role": "validation" } ] },
 *       { "name": "ama", "source": "clipdir",   the authors' clip folders (tcb/sequence.h,
 *         "root": "data/AMA",               tcb_sequence_read_clipdir): <root>/<clip>/gt/NNNN.obj
 *         "normalization": "none",          and pcl_seqs/NNNN.npy; their coordinates by default
 *         "sequences": [ { "name": "crane_0010", "role": "test" } ] },
 *       { "name": "dfaust", "source": "pcl_seq",  Occupancy Flow's point clouds (no faces):
 *         "root": "data/Humans/D-FAUST",     <root>/<sequence>/pcl_seq/NNNNNNNN.npz
 *         "points": 10000,                  the points kept, the same in every frame (0: all)
 *         "sequences": [ { "name": "50002_light_hopping_loose", "role": "test" } ] } ],
 *     "methods": [ { "name": "oracle" },
 *                  { "name": "mine", "method": "external",   a program of yours (docs/adding-a-method.md §6);
 *                    "params": { "command": ["mine.py", "--x"], a .py script runs under params "python", else
 *                                "python": "venv/bin/python" } }, $TCBENCH_PYTHON, else python3 from PATH
 *                  { "name": "mca-cpu", "method": "mca", "params": { … },
 *                    "seeds": [0, 1, 2],          its own seeds instead of the config's
 *                    "datasets": ["dfaust"] } ] } only on these datasets (default: all)
 * Unknown keys anywhere are errors. */
#ifndef TCB_CONFIG_H
#define TCB_CONFIG_H

#include <stddef.h>
#include <stdint.h>

#include "tcb/error.h"
#include "tcb/fsutil.h"
#include "tcb/metrics.h"
#include "tcb/sequence.h"
#include "tcb/split.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum tcb_source {
    TCB_SOURCE_SYNTHETIC,
    TCB_SOURCE_OBJDIR,
    TCB_SOURCE_DFAUST,
    TCB_SOURCE_CLIPDIR,
    TCB_SOURCE_PCL_SEQ
} tcb_source;

typedef struct tcb_sequence_spec {
    char name[TCB_NAME_MAX];
    tcb_role role;
    /* A clip fitted on its own ("evaluation.fit": "per_clip"): frames
     * start .. start + TCB_CLIP_FRAMES - 1 of the dataset's sequence
     * clip_of, as a sequence of its own named `name` ("crane_0010");
     * clip_of is "" for a whole sequence. */
    char clip_of[TCB_NAME_MAX];
    int start;
} tcb_sequence_spec;

/* pcl_seq: the points a frame keeps by default (the rank metric compares
 * every vertex with every other: Occupancy Flow's 100 000 would be 10^10
 * distances a pair). */
#define TCB_PCL_SEQ_DEFAULT_POINTS 10000

typedef struct tcb_dataset_spec {
    char name[64];
    tcb_source source;
    char root[TCB_PATH_MAX];
    uint64_t seed;           /* synthetic generator seed */
    int frames;              /* synthetic: 0 = default length */
    tcb_normalization norm;
    int align_rotation;      /* tcb/align.h after the normalization */
    int align_samples;       /* its vertex subset; 0 without align_rotation */
    int with_replacement;
    int optional;
    int points;              /* pcl_seq: the points kept a frame (0: all) */
    int n_subjects;          /* dfaust: the listed subjects; 0 = every one found */
    char **subjects;
    int n_sequences;
    tcb_sequence_spec *sequences;
} tcb_dataset_spec;

typedef struct tcb_method_spec {
    char label[64];          /* "name": unique within the config, used in results */
    char method[64];         /* registered method ("method", default = label) */
    char *params_json;       /* compact JSON object text, "{}" by default */
    int n_seeds;             /* the cells to run: the method's "seeds", else the config's */
    int *seeds;
    int n_only_on;           /* "datasets": the datasets it runs on; 0: all of them */
    char (*only_on)[64];
    char plugin_digest[17];  /* "plugin_fnv1a64": the plug-in build its cells were computed
                              * with, as a run directory records it; "" when not given */
} tcb_method_spec;

/* Whether method m has cells on the dataset named `dataset`. */
int tcb_method_runs_on(const tcb_method_spec *m, const char *dataset);

#define TCB_REFERENCE_TABLES_MAX 16

/* The evaluation protocols, a set ("evaluation.protocol"). */
enum { TCB_PROTOCOL_PAIRS = 1, TCB_PROTOCOL_CLIPS = 2 };

typedef struct tcb_config {
    char path[TCB_PATH_MAX];
    char name[64];
    char output[TCB_PATH_MAX];
    char splits_dir[TCB_PATH_MAX];
    char cache_dir[TCB_PATH_MAX];
    int n_plugins;
    char **plugins;
    int n_seeds;
    int *seeds;
    int threads;
    int eval_pairs;
    uint64_t split_seed;
    int protocols;           /* TCB_PROTOCOL_* bits, never 0 */
    int fit_per_clip;        /* "fit": "per_clip": every sequence of the grid is one clip,
                              * fitted on its own (clip protocol only) */
    tcb_input_normals input_normals; /* the normals input clouds come with */
    tcb_recon_frame recon_frame;     /* the frame of the reconstruction metrics */
    int eval_clips;          /* clips per sequence under the clip protocol */
    int surface_samples;     /* samples per mesh of the reconstruction metrics */
    int pool_size;
    uint64_t pool_seed;
    int input_points;
    int n_datasets;
    tcb_dataset_spec *datasets;
    int n_methods;
    tcb_method_spec *methods;
    char reference[32];      /* "reference.source"; "" when the config names none */
    int n_reference_tables;
    char reference_tables[TCB_REFERENCE_TABLES_MAX][16];
    char *json_text;         /* the normalized config, saved beside the results */
} tcb_config;

/* What the command line changes before the config is read. */
typedef struct tcb_root_override {
    const char *dataset;     /* a dataset's "name" */
    const char *dir;         /* its root */
} tcb_root_override;

typedef struct tcb_config_opts {
    const char *variant;     /* NULL: the config's first variant, if it has any */
    int n_roots;
    const tcb_root_override *roots;
} tcb_config_opts;

int tcb_config_load(const char *path, tcb_config *out, tcb_error *err);
int tcb_config_parse(const char *text, const char *origin, tcb_config *out, tcb_error *err);
/* The same with the command line's choices; opts NULL is as above: the
 * first variant, roots from the environment or the config. */
int tcb_config_load_opts(const char *path, const tcb_config_opts *opts, tcb_config *out,
                         tcb_error *err);
int tcb_config_parse_opts(const char *text, const char *origin, const tcb_config_opts *opts,
                          tcb_config *out, tcb_error *err);
/* "TCBENCH_ROOT_<NAME>" for dataset `name`. */
void tcb_config_root_env_name(const char *dataset, char *out, size_t size);
void tcb_config_free(tcb_config *c);

/* The dataset and its sequence of those names in c; TCB_ERR_INPUT when
 * either is missing (*d stays NULL when the dataset is: the message says
 * which). */
int tcb_config_find_sequence(const tcb_config *c, const char *dataset, const char *sequence,
                             const tcb_dataset_spec **d, const tcb_sequence_spec **s, tcb_error *err);

/* Value names of the config's enums, NULL-terminated; indexed by the enum. */
extern const char *const tcb_config_source_names[];   /* tcb_source */
extern const char *const tcb_config_norm_names[];     /* tcb_normalization */
extern const char *const tcb_config_protocol_names[]; /* by TCB_PROTOCOL_* bit position */
extern const char *const tcb_config_sampling_names[]; /* with_replacement: 0, 1 */
extern const char *const tcb_config_fit_names[];      /* fit_per_clip: 0, 1 */
extern const char *const tcb_config_input_normals_names[]; /* tcb_input_normals */

/* The config with every default filled in, pretty-printed (what a run
 * directory records of it); malloc'ed, NULL
 * when out of memory. (config/config_dump.c) */
char *tcb_config_normalized_json(const tcb_config *c);

#ifdef __cplusplus
}
#endif
#endif
