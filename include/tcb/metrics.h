/* tcbench — correspondence and reconstruction metrics, exactly as the
 * authors' evaluation code computes them (reference-protocol §5.4–§5.6).
 *
 * Per pair (i → j) every GT vertex q^i_k is transferred by the method to a
 * point on frame j, then projected to its nearest GT vertex of j, giving a
 * predicted vertex id pred[k]. With d_k = ||q^j_pred[k] − q^j_k||²:
 *   m_sL2  = mean_k sqrt(d_k)              (code; ×1e3 in tables)
 *   sL2²   = mean_k d_k                    (the paper's literal formula, stored alongside)
 *   rank   = mean_k #{l : ||q^j_l − q^j_k||² < d_k} / K   (×100)
 *   PCK_s  = frac_k [d_k ≤ t_s], t_s = linspace(0, 0.02, 100) on SQUARED distances
 *   AUC    = mean_s PCK_s                  (×100)
 *   CD     = mean_a min_b |a−b|² + mean_b min_a |a−b|²   (×1e3)
 * sL2 and rank mean ± std are pooled over all vertices of all pairs; AUC and
 * CD mean ± std are over pairs (numpy std, ddof = 0).
 *
 * Beside them, not part of the paper's protocol: the geodesic error m_geo
 * and its PCK curve (tcb/geodesic.h computes them), pooled the same way. */
#ifndef TCB_METRICS_H
#define TCB_METRICS_H

#include <stdint.h>

#include "tcb/error.h"
#include "tcb/rng.h"

#ifdef __cplusplus
extern "C" {
#endif

#define TCB_PCK_STEPS 100
#define TCB_PCK_MAX 0.02
/* The geodesic PCK: thresholds on the normalised geodesic error (not
 * squared), the range of Kim et al. 2011's plots. */
#define TCB_GEO_PCK_STEPS 100
#define TCB_GEO_PCK_MAX 0.25

/* Running mean / variance (Welford; Chan et al. to merge). std uses ddof = 0. */
typedef struct tcb_stat {
    double n;
    double mean;
    double m2;
} tcb_stat;

void tcb_stat_push(tcb_stat *s, double x);
void tcb_stat_merge(tcb_stat *into, const tcb_stat *other);
double tcb_stat_std(const tcb_stat *s);

/* Threshold s of the PCK curve: linspace(0, TCB_PCK_MAX, TCB_PCK_STEPS)[s]. */
double tcb_pck_threshold(int s);
/* Threshold s of the geodesic PCK: linspace(0, TCB_GEO_PCK_MAX, TCB_GEO_PCK_STEPS)[s]. */
double tcb_geo_pck_threshold(int s);

/* pck[s] = frac_k [d[k] <= threshold(s)] over d[0 .. n), s < steps; *auc =
 * mean_s pck[s]. */
void tcb_pck_curve(const double *d, int n, double (*threshold)(int), int steps, double *pck,
                   double *auc);

typedef struct tcb_pair_metrics {
    tcb_stat sl2;               /* per-vertex Euclidean error */
    tcb_stat sl2sq;             /* per-vertex squared error */
    tcb_stat rank;              /* per-vertex normalized rank in [0, 1) */
    double pck[TCB_PCK_STEPS];  /* fractions */
    double auc;                 /* mean of pck, in [0, 1] */
    /* Geodesic error (tcb_pair_geodesic_compute); geo.n = 0 when not computed. */
    tcb_stat geo;               /* per-vertex normalised geodesic error */
    double geo_pck[TCB_GEO_PCK_STEPS];
    double geo_auc;
    int geo_unreachable;        /* vertices scored by the Euclidean fallback */
} tcb_pair_metrics;

/* Step 2 of the transfer: idx[k] = nearest GT vertex of frame j to pts[k]. */
int tcb_project_to_vertices(const float *verts_j, int nv, const float *pts, int n,
                            int32_t *idx, tcb_error *err);

/* Metrics of one pair from predicted vertex ids (pred[k] ∈ [0, nv)):
 * tcb_pair_vertex_metrics, then tcb_pair_metrics_summarize. */
int tcb_pair_metrics_compute(const float *verts_j, int nv, const int32_t *pred,
                             tcb_pair_metrics *out, tcb_error *err);

/* The per-vertex values the pair's metrics summarize: sq[k] = d_k and
 * rank[k] (a fraction), each [nv]; rank may be NULL (not computed, the
 * costly part). Errors as tcb_pair_metrics_compute's. */
int tcb_pair_vertex_metrics(const float *verts_j, int nv, const int32_t *pred, double *sq,
                            double *rank, tcb_error *err);
/* The pair's metrics from those values (sL2 is sqrt of each sq[k]). */
void tcb_pair_metrics_summarize(const double *sq, const double *rank, int nv, tcb_pair_metrics *out);

/* Symmetric Chamfer distance of squared nearest-neighbour distances (means). */
int tcb_chamfer(const float *a, int na, const float *b, int nb, double *out,
                tcb_error *err);

/* The atlas transfer f = π_Pj ∘ φ_j ∘ φ_i⁻¹ ∘ π_φi over discrete samples
 * (§5.4 steps 1–2 without the final projection): pred_i and pred_j are the
 * predicted surface points of frames i and j at the SAME m UV samples; each
 * src point goes to pred_j[argmin_m |src − pred_i[m]|]. out is [n][3]. */
int tcb_atlas_transfer(const float *src, int n, const float *pred_i, const float *pred_j,
                       int m, float *out, tcb_error *err);

/* The reconstruction metrics of the 2024-2026 papers (DynoSurf's
 * evaluation/utils.py, eval_mesh and eval_pointcloud, after Occupancy
 * Networks' eval.py), on the surface a method gives of one frame
 * (tcb_method_ops.surface) against the frame's GT mesh, each sampled with
 * n area-uniform points carrying their face's unit normal. With
 * acc_p = |p − nearest GT sample| for each predicted sample p and
 * comp_q = |q − nearest predicted sample| for each GT sample q:
 *   cdl2     = 0.5 (mean_p acc_p² + mean_q comp_q²)
 *   nc       = 0.5 (mean_p |n_p · n_gt(p)| + mean_q |n_q · n_pred(q)|)
 *   fscore_t = 2 P R / (P + R), P = frac_p [acc_p ≤ t], R = frac_q [comp_q ≤ t]
 *              (0 when P + R = 0), t = 0.005 and 0.01 in the sequence's
 *              normalized units (docs/protocol.md, "Reconstruction metrics"). */
enum { TCB_RECON_CDL2, TCB_RECON_NC, TCB_RECON_FSCORE05, TCB_RECON_FSCORE1, TCB_N_RECON };
#define TCB_FSCORE_T05 0.005
#define TCB_FSCORE_T1 0.01
#define TCB_DEFAULT_SURFACE_SAMPLES 100000

/* The frame the reconstruction metrics are measured in: the sequence's
 * (its normalization), or each frame's own GT box: centred on the box's
 * centre, its largest extent 1 (Neu-PiG's evaluation, after Occupancy
 * Networks'; the F-score thresholds are then 0.5 % and 1 % of it). */
typedef enum tcb_recon_frame { TCB_RECON_FRAME_SEQUENCE = 0, TCB_RECON_FRAME_BOX = 1 } tcb_recon_frame;
extern const char *const tcb_recon_frame_names[]; /* "sequence", "frame_box"; NULL-terminated */

/* The map of TCB_RECON_FRAME_BOX for a frame of n GT vertices [n][3]:
 * x -> (x - centre) * scale, scale = 1 / the box's largest extent (0 for
 * a frame of no extent). */
void tcb_frame_box_map(const float *gt, int n, double centre[3], double *scale);
/* pts[n][3] mapped in place. */
void tcb_frame_box_apply(const double centre[3], double scale, float *pts, int n);

/* "cdl2", "nc", "fscore05", "fscore1": the cell's keys, in enum order. */
extern const char *const tcb_recon_names[TCB_N_RECON];

/* n samples of a triangle mesh (tcb_sample_surface_faces) into pts [n][3]
 * and the unit normal of each one's face into normals [n][3]. */
int tcb_recon_sample(const float *verts, const int32_t *faces, int nf, int n, tcb_rng *rng,
                     float *pts, float *normals, tcb_error *err);

/* The metrics above of predicted samples (pred, pred_n: [np][3]) against
 * GT samples (gt, gt_n: [ng][3]); out in enum order. Nearest neighbours by
 * tcb/nn.h, their distances recomputed in double. */
int tcb_recon_metrics(const float *pred, const float *pred_n, int np, const float *gt,
                      const float *gt_n, int ng, double out[TCB_N_RECON], tcb_error *err);

/* Everything measured on one (dataset, sequence, method, seed) cell. */
typedef struct tcb_summary {
    int n_pairs;
    tcb_stat sl2, sl2sq, rank;   /* pooled over all vertices of all pairs */
    tcb_stat auc;                /* over pairs */
    tcb_stat cd;                 /* over pairs; n = 0 when the method has no reconstruction */
    double pck[TCB_PCK_STEPS];   /* mean curve over pairs */
    /* Geodesic error, over the pairs that have it (geo_auc.n of them: all
     * pairs of a cell scored since it exists, none of an older cell). */
    tcb_stat geo;                /* pooled over all vertices of those pairs */
    tcb_stat geo_auc;            /* over those pairs */
    double geo_pck[TCB_GEO_PCK_STEPS]; /* mean curve over those pairs */
    double geo_unreachable;      /* vertices scored by the Euclidean fallback, summed */
    /* The clip protocol's tracking error Corr (tcb_corr_frame averaged over
     * a clip's frames 1-16), over clips; n = 0 when no clip was scored (a
     * pairs-only run, an older cell). */
    tcb_stat corr;
    /* DynoSurf's Corr as its evaluation computes it (tcb_corr_mesh_match),
     * over the clips of a method whose surfaces share one topology
     * through the clip; n = 0 otherwise (or an older cell). */
    tcb_stat corr_mesh;
    /* The reconstruction metrics (TCB_RECON_*), over the cell's evaluated
     * frames; n = 0 when the method gives no surface (or an older cell). */
    tcb_stat recon[TCB_N_RECON];
} tcb_summary;

/* The clip protocol's tracking error at one frame t of a clip (DynoSurf's
 * evaluation/utils.py, eval_correspondences_mesh): the mean over k < n of
 * the un-squared Euclidean distance |moved[k] - truth[k]| between where the
 * method carried point k of the clip's frame 0 and its true position on
 * frame t, summed in double. Corr of a clip is the mean of this over
 * t = 1 .. 16 (docs/protocol.md, "The clip protocol"). */
double tcb_corr_frame(const float *moved, const float *truth, int n);

/* DynoSurf's Corr of a clip of surfaces with one topology (its
 * evaluation/utils.py, eval_correspondences_mesh): each vertex i of the
 * method's frame-0 surface is matched to its nearest GT point of frame 0,
 * ind[i] (pred0 [n][3], gt0 [ng][3]); at frame t the error is then the
 * mean over i of |pred_t[i] - gt_t[ind[i]]| (tcb_corr_mesh_frame), and
 * the clip's value their mean over t = 1 .. 16. */
int tcb_corr_mesh_match(const float *pred0, int n, const float *gt0, int ng, int32_t *ind, tcb_error *err);
double tcb_corr_mesh_frame(const float *pred_t, int n, const float *gt_t, const int32_t *ind);

void tcb_summary_init(tcb_summary *s);
/* cd: the pair's Chamfer distance, or NAN when there is none. */
void tcb_summary_add_pair(tcb_summary *s, const tcb_pair_metrics *m, double cd);
void tcb_summary_merge(tcb_summary *into, const tcb_summary *other);

#ifdef __cplusplus
}
#endif
#endif
