/* Private to metrics/: the shortest-path search behind tcb/geodesic.h,
 * shared by the per-pair queries (geodesic.c) and the landmarks
 * (geodesic_landmarks.c). */
#ifndef TCB_METRICS_GEODESIC_INTERNAL_H
#define TCB_METRICS_GEODESIC_INTERNAL_H

#include <stddef.h>
#include <stdint.h>

#include "tcb/geodesic.h"

/* Landmarks of the ALT heuristic (Goldberg & Harrelson, SODA 2005): 16
 * keeps a vertex's distances in two cache lines and, measured on the crane
 * with random predictions, most of the gain (bench/bench_geodesic.c). */
#define TCB_GEO_LANDMARKS 16

typedef struct tcb_geo_heap_entry {
    double f;   /* g + h when pushed: stale once above the vertex's g + h */
    int32_t v;
} tcb_geo_heap_entry;

/* One thread's search state over an n-vertex graph. Per-vertex entries are
 * valid only where their stamp equals `cur`, so starting a search costs
 * nothing and a search costs what it explores. */
typedef struct tcb_geo_ws {
    int n;
    double *g;          /* [n] tentative distance, valid where seen[v] == cur */
    double *h;          /* [n] heuristic towards the current target, valid where hseen[v] == cur */
    uint32_t *seen, *hseen;
    uint32_t *goal;     /* [n] == cur: a target of the current search, not yet settled */
    uint32_t cur;
    tcb_geo_heap_entry *heap;
    size_t n_heap, cap;
    long long expanded; /* vertices expanded, summed over searches: the work done */
} tcb_geo_ws;

/* The frame a search runs on, and what guides it. */
typedef struct tcb_geo_view {
    const tcb_edge_graph *g;
    const double *w;      /* [2 n_edges] edge lengths */
    const float *verts;   /* [n][3]: the Euclidean heuristic's coordinates */
    const double *lm;     /* [n][TCB_GEO_LANDMARKS] landmark distances, or NULL */
    double lm_slack;      /* subtracted from the landmark bound (rounding) */
} tcb_geo_view;

int tcb_geo_ws_init(tcb_geo_ws *ws, int n);
void tcb_geo_ws_free(tcb_geo_ws *ws);
/* Starts a search: every vertex unvisited, no goals, empty heap. */
void tcb_geo_ws_next(tcb_geo_ws *ws);

/* From src until the m goals marked in ws->goal (goal[v] = cur after
 * tcb_geo_ws_next) are settled, m = 0: the whole component; their
 * distances are then final in ws->g. target >= 0 (then the only goal)
 * guides the search towards it: A* with the larger of the Euclidean and
 * the landmark bound. Returns the goals left unsettled (0 when all were
 * reached), or -1 when out of memory. */
int tcb_geo_search(const tcb_geo_view *gv, tcb_geo_ws *ws, int32_t src, int m, int32_t target);

/* Landmark distances for view gv (its w and g): farthest-point sampling in
 * the largest component; *out is [n][TCB_GEO_LANDMARKS] (malloc'ed), 0
 * outside that component, *slack the rounding margin. -1 when out of memory. */
int tcb_geo_landmarks(const tcb_geo_view *gv, double **out, double *slack);

#endif
