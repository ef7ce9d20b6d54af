/* tcbench — the results store: one JSON file per cell, written atomically.
 *
 * Layout of a run directory:
 *     <run>/config.json                                  the configs as run: the union of
 *         their datasets, sequences, methods and seeds; a run that would change cells
 *         already there is refused (harness/run_config.c)
 *     <run>/cells/<dataset>/<sequence>/<method>/seed_<s>.json
 *     <run>/work/<dataset>/<sequence>/<method>/seed_<s>/  method checkpoints
 *         (model.ckpt after fit, model.ckpt.fit.json its record: the cell
 *         and sequence it was made for, its size and hash, its fit time;
 *         and a method's own training state while it fits)
 *     <run>/report/                                      written by `tcbench report`
 * A cell file exists only once the cell finished (ok, failed or diverged);
 * `tcbench run` skips cells whose file holds a result (ok, or diverged: a
 * diverged training is the method's result), so a killed run resumes, and
 * computes failed cells again (failed: no result — the method crashed,
 * timed out, wrote bad output or refused its input).
 *
 * Cell file format "tcbench-cell/1" (all metric values in raw units:
 * distances in normalized shape units, rank/auc/pck as fractions):
 *   { "format", "dataset", "sequence", "role", "method", "method_impl",
 *     "params": {…}, "seed", "status": "ok"|"failed"|"diverged", "message",
 *     "git_revision", "tcbench_version",
 *     "timings": {"load_s", "fit_s", "eval_s"}, "peak_rss_kb",
 *         (fit_s is the whole fit across processes: a resumed training adds
 *         what its checkpoint had cost, a reused model checkpoint reports the
 *         fit time recorded beside it; peak_rss_kb is this process's)
 *     "split": {"path", "seed", "n_pairs"},
 *     "summary": {"n_pairs", "sl2": {"n","mean","m2"}, "sl2sq": {…},
 *                 "rank": {…}, "auc": {…}, "cd": {…} | null, "pck": [100],
 *                 "geo": {…}, "geo_auc": {…}, "geo_pck": [100], "geo_unreachable"},
 *     "pair_columns": ["i","j","n","sl2","sl2_m2","sl2sq","sl2sq_m2",
 *                      "rank","rank_m2","auc","cd",
 *                      "geo","geo_m2","geo_auc","geo_unreachable"],
 *     "pairs": [[…], …] }                    (cd is null without reconstruction)
 * "message" says why a failed or diverged cell failed; a cell written by
 * `tcbench score` (tcb/score.h) says "scored from files" there, with
 * method_impl "scored" and params {"pred_dir": …} ({"pred_file": …} from an
 * .npz; {"pred": "memory"} and message "scored from memory" from a binding).
 * The geodesic keys (tcb/geodesic.h: geo is the normalised geodesic error,
 * geo_unreachable the count of vertices scored by the Euclidean fallback)
 * came later in the same format: a cell file without them (the four
 * summary keys absent, 11 pair columns) still loads, with geo.n = 0 and
 * geo_auc.n = 0, and reports show "-" for its geodesic columns. A pair's
 * geodesic columns are null when it has none.
 * The clip protocol (docs/protocol.md, "The clip protocol") came later
 * too: a cell that scored clips has "summary.corr" ({n, mean, m2} over its
 * clips) and a top-level
 *     "clips": {"path", "seed", "clip_frames": 17, "n_clips",
 *               "columns": ["start", "corr", "err"],
 *               "rows": [[start, corr, [err_1, …, err_16]], …]}
 * (err_t: tcb_corr_frame at the clip's frame t; corr their mean); a cell
 * without clips has neither key (n_clips 0, corr.n 0: "-" in the Corr
 * column), and a clips-only cell has no pairs (split.n_pairs 0).
 * A cell of a plug-in's method (tcb/registry.h) records which build ran
 * it: "plugin": {"path", "fnv1a64", "abi", "version"} (the file, its
 * digest, the table's abi_version and version string, "" when it has
 * none); a built-in method's cell, and one written before the key, has
 * none (plugin_path "").
 * A cell whose method took normals with its input points says which:
 * "normals": "gt" | "estimated" (absent: points only, or written before).
 * A cell of a sequence without faces (a "pcl_seq" dataset: points alone)
 * says so, "faces": false (absent: the sequence has faces, or the cell was
 * written before the key): its geodesic and reconstruction metrics are not
 * applicable, and reports say so instead of leaving their columns blank.
 * The reconstruction metrics (tcb/metrics.h, TCB_RECON_*; docs/protocol.md,
 * "Reconstruction metrics") came later too: a cell whose method gives
 * surfaces has "summary.cdl2", "summary.nc", "summary.fscore05" and
 * "summary.fscore1" ({n, mean, m2} over its evaluated frames) and
 *     "surface": {"samples": 100000, "frame": "frame_box" (absent: "sequence"),
 *                 "columns": ["frame", "cdl2", "nc", "fscore05", "fscore1"],
 *                 "rows": [[frame, cdl2, nc, fscore05, fscore1], …]}
 * one row per evaluated frame (every frame of its pairs and clips, once,
 * ascending); a cell without has none of these keys (n_surface 0: "-"). */
#ifndef TCB_RESULTS_H
#define TCB_RESULTS_H

#include <stddef.h>

#include "tcb/error.h"
#include "tcb/metrics.h"
#include "tcb/split.h"

#ifdef __cplusplus
extern "C" {
#endif

#define TCB_CELL_FORMAT "tcbench-cell/1"

typedef enum tcb_cell_status { TCB_CELL_OK, TCB_CELL_FAILED, TCB_CELL_DIVERGED } tcb_cell_status;

const char *tcb_cell_status_name(tcb_cell_status s);

typedef struct tcb_pair_record {
    int i, j;
    tcb_stat sl2, sl2sq, rank; /* over the pair's vertices */
    double auc;
    double cd;                 /* NAN when the method has no reconstruction */
    tcb_stat geo;              /* normalised geodesic error; n = 0: not scored (an older cell) */
    double geo_auc;
    int geo_unreachable;       /* vertices scored by the Euclidean fallback */
} tcb_pair_record;

/* The reconstruction metrics of one evaluated frame. */
typedef struct tcb_surface_record {
    int frame;
    double v[TCB_N_RECON];             /* TCB_RECON_* order */
} tcb_surface_record;

/* One clip of the clip protocol: frames start .. start + TCB_CLIP_FRAMES - 1. */
typedef struct tcb_clip_record {
    int start;                          /* the clip's frame 0 */
    double corr;                        /* mean of err */
    double err[TCB_CLIP_FRAMES - 1];    /* tcb_corr_frame at the clip's frames 1 .. 16 */
    double corr_mesh;                   /* DynoSurf's Corr (tcb_corr_mesh_match); NAN: the method's
                                         * surfaces are not of one topology, or it has none */
} tcb_clip_record;

typedef struct tcb_cell_result {
    char dataset[64];
    char sequence[128];
    char role[16];             /* "train" | "validation" | "test" */
    char method[64];           /* the config's label for the method */
    char method_impl[64];      /* the registered method name */
    char plugin_path[4096];    /* a plug-in's method: the file it came from; "" built in */
    char plugin_digest[17];    /* and the file's FNV-1a 64 (hex) when the cell ran */
    int plugin_abi;            /* and its table's abi_version */
    char plugin_version[64];   /* and its version string (tcb_method_ops.version; "" none) */
    char normals[16];          /* the normals the method took with its input points
                                * (tcb_method_normals: "gt", "estimated"); "" none */
    int no_faces;              /* 1: the sequence has no faces ("faces": false) */
    char *params_json;         /* malloc'ed, compact JSON object */
    int seed;
    tcb_cell_status status;
    char message[TCB_ERRMSG_MAX];
    char git_revision[64];
    char tcbench_version[32];  /* the version that wrote the file; "" in a new cell: the
                                * writer records its own (TCB_VERSION) */
    double load_s, fit_s, eval_s;
    long peak_rss_kb;
    char split_path[4096];
    unsigned long long split_seed;
    int n_pairs;
    tcb_pair_record *pairs;    /* malloc'ed [n_pairs] */
    tcb_summary summary;
    /* The clip protocol; n_clips = 0: no clips scored (summary.corr.n 0). */
    char clips_path[4096];
    unsigned long long clips_seed;
    int n_clips;
    tcb_clip_record *clips;    /* malloc'ed [n_clips] */
    /* The reconstruction metrics per evaluated frame; n_surface = 0: none
     * (a method without surfaces, an older cell; summary.recon[].n 0). */
    int surface_samples;       /* samples per mesh */
    tcb_recon_frame surface_frame; /* the frame they were measured in */
    int n_surface;
    tcb_surface_record *surface; /* malloc'ed [n_surface], ascending frame */
} tcb_cell_result;

/* <run>/cells/<dataset>/<sequence>/<method>/seed_<seed>.json */
int tcb_cell_path(char *out, size_t size, const char *run_dir, const char *dataset,
                  const char *sequence, const char *method, int seed, tcb_error *err);

int tcb_cell_save(const char *path, const tcb_cell_result *c, tcb_error *err);
/* Validates format and fields; errors name the file and key. */
int tcb_cell_load(const char *path, tcb_cell_result *out, tcb_error *err);
void tcb_cell_free(tcb_cell_result *c);
/* Frees the cell's rows (pairs, clips, surface frames) and counts them 0,
 * keeping its identity: what a failed cell keeps. */
void tcb_cell_drop_rows(tcb_cell_result *c);

/* Every cell file under <run>/cells, sorted by (dataset, sequence, method, seed).
 * *cells is malloc'ed; free each with tcb_cell_free, then the array. */
int tcb_results_scan(const char *run_dir, tcb_cell_result **cells, int *n, tcb_error *err);

#ifdef __cplusplus
}
#endif
#endif
