/* tcbench — geodesic error of a correspondence, beside the paper's
 * Euclidean metrics (an addition to the ICCV'21 protocol, not part of it;
 * docs/protocol.md, "Geodesic error").
 *
 * Per pair i → j and vertex k of frame i's GT, with pred[k] the predicted
 * vertex of frame j (the same ids tcb_pair_metrics_compute scores):
 *   e_k   = d_j(pred[k], k) / sqrt(area_j)        (Kim, Lipman, Funkhouser,
 *           "Blended Intrinsic Maps", SIGGRAPH 2011: normalised by the
 *           square root of the surface area)
 *   m_geo = mean_k e_k                            (×1e3 in tables)
 *   PCK^geo_s = frac_k [e_k ≤ t_s], t_s = linspace(0, 0.25, 100) on the
 *           (unsquared) normalised distance;   AUC_geo = mean_s PCK^geo_s
 * m_geo mean ± std pool every vertex of every pair, AUC_geo is over pairs,
 * as m_sL2 and AUC are.
 *
 * d_j is the exact shortest-path distance on frame j's EDGE GRAPH: the
 * vertices, and an edge for every side of every face, weighted by its
 * Euclidean length in frame j (double, from the float vertices). It is an
 * upper bound of the true surface geodesic (paths may not cross faces):
 * on a regular triangle grid it overestimates by up to 2/√3 ≈ 1.155 in the
 * directions halfway between edges, by nothing along them, and refining
 * the mesh does not shrink that factor. It is exact, reproducible and the
 * same for every method; no refinement (fast marching, Steiner points) is
 * applied.
 *
 * Unreachable pairs. Where pred[k] and k lie in different connected
 * components of the graph (a mesh made of several pieces, or a vertex on no
 * face: an isolated vertex is a component of its own), no path exists.
 * Then d_j(pred[k], k) is the Euclidean distance |q_pred[k] − q_k| of
 * frame j: finite, defined for every input, and a lower bound of any path
 * (a method is never punished beyond what a straight bridge between the
 * pieces would cost). Such vertices are counted (geo_unreachable) so a
 * report can say how many were scored this way. pred[k] = k is 0 whatever
 * the vertex. A geodesic value is therefore never inf or NaN.
 *
 * Cost. Only vertices with pred[k] != k need a search. The queries are
 * grouped by predicted vertex (the source): a source with few queries
 * answers each by A* towards it, one with many (a method mapping many
 * vertices to one) by a single Dijkstra that stops once they are all
 * settled. A* is guided by the straight-line distance and, when a probe
 * (32 sources spread over the pair's) says the queries are long (a bad
 * method), also by landmark distances (ALT), which follow the surface. Both bounds
 * are admissible, so every distance is Dijkstra's. Sources run in
 * parallel (OpenMP), each query independent, and every choice depends on
 * the pair alone: results do not depend on the thread count. Measured by
 * bench/bench_geodesic.c (docs/protocol.md quotes it).
 *
 * Memory. The graph's topology serves every frame (they share the faces),
 * so the harness builds it once per cell: about 4(2·nv + 2·n_edges) bytes.
 * The edge lengths of a frame are recomputed per pair (8 bytes per
 * directed edge) rather than kept per frame: that costs one sqrt per edge,
 * far less than the searches, and keeps DFAUST's thousands of frames out of
 * memory. A pair that builds landmarks holds 16 doubles per vertex while it
 * is scored. */
#ifndef TCB_GEODESIC_H
#define TCB_GEODESIC_H

#include <stdint.h>

#include "tcb/error.h"
#include "tcb/metrics.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The undirected edge graph of a triangle list, as CSR adjacency. */
typedef struct tcb_edge_graph {
    int n_verts;
    int n_edges;          /* undirected edges; adj holds each twice */
    int32_t *offsets;     /* [n_verts + 1]: neighbours of v are adj[offsets[v] .. offsets[v + 1]) */
    int32_t *adj;         /* [2 n_edges], ascending within each vertex */
    int n_components;
    int32_t *component;   /* [n_verts]: component id, numbered in order of each one's lowest vertex */
} tcb_edge_graph;

/* The graph of faces [nf][3] over nv vertices; degenerate sides (a face
 * repeating a vertex) add no edge, shared sides one. Vertex ids outside
 * [0, nv) are an input error naming the face. */
int tcb_edge_graph_build(const int32_t *faces, int nf, int nv, tcb_edge_graph *out,
                         tcb_error *err);
void tcb_edge_graph_free(tcb_edge_graph *g);

/* w[e] = |v_a − v_b| for every entry e = (a, b = adj[e]) of the CSR, from
 * the float vertices [n_verts][3] in double ((dx² + dy²) + dz² with
 * d = (double)a − (double)b, as the Euclidean metrics). Symmetric exactly. */
void tcb_edge_graph_lengths(const tcb_edge_graph *g, const float *verts, double *w);

/* Shortest-path distance from src to every vertex (plain Dijkstra over the
 * whole graph, no early exit); INFINITY where unreachable. The reference
 * the per-pair searches are tested against and the benchmark's peer. */
int tcb_geodesic_field(const tcb_edge_graph *g, const double *w, int src, double *dist,
                       tcb_error *err);

/* dist[k] = shortest-path distance on the frame `verts` between pred[k] and
 * k, for every vertex k (pred[k] ∈ [0, n_verts)); the Euclidean distance
 * where they are in different components, counted in *n_unreachable (may be
 * NULL). w: the frame's edge lengths (tcb_edge_graph_lengths). */
int tcb_geodesic_to_pred(const tcb_edge_graph *g, const double *w, const float *verts,
                         const int32_t *pred, double *dist, int *n_unreachable, tcb_error *err);

/* The geodesic fields of *out (geo, geo_pck, geo_auc, geo_unreachable) for
 * the pair whose target frame has vertices verts_j and surface area area_j
 * (> 0; tcb_sequence.areas[j]); the other fields are left as they are, so
 * call it after tcb_pair_metrics_compute. verr (may be NULL) receives each
 * vertex's normalised error e_k [n_verts]. */
int tcb_pair_geodesic_compute(const tcb_edge_graph *g, const float *verts_j, double area_j,
                              const int32_t *pred, tcb_pair_metrics *out, double *verr,
                              tcb_error *err);

#ifdef __cplusplus
}
#endif
#endif
