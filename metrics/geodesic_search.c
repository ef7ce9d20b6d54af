/* The one shortest-path search of the geodesic error: Dijkstra with a lazy
 * binary heap (superseded entries are skipped when popped), stopping once
 * its goals are settled; with a single target, A* guided by a lower bound
 * of the distance left. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "metrics/geodesic_internal.h"

/* The Euclidean bound is shrunk by this relative margin. Unshrunk it is
 * admissible and consistent in exact arithmetic (a straight line is never
 * longer than a path of straight edges), but the path lengths it is
 * compared with are rounded sums: a relative 1e-9 covers their rounding
 * for paths of up to ~1e6 edges, so a search stops only when the target's
 * distance is final. */
#define EUCLID_SHRINK (1.0 - 1e-9)

void tcb_geo_ws_free(tcb_geo_ws *ws)
{
    free(ws->g);
    free(ws->h);
    free(ws->seen);
    free(ws->hseen);
    free(ws->goal);
    free(ws->heap);
    memset(ws, 0, sizeof *ws);
}

int tcb_geo_ws_init(tcb_geo_ws *ws, int n)
{
    memset(ws, 0, sizeof *ws);
    ws->n = n;
    ws->g = malloc((size_t)n * sizeof *ws->g);
    ws->h = malloc((size_t)n * sizeof *ws->h);
    ws->seen = calloc((size_t)n, sizeof *ws->seen);
    ws->hseen = calloc((size_t)n, sizeof *ws->hseen);
    ws->goal = calloc((size_t)n, sizeof *ws->goal);
    ws->cap = 256;
    ws->heap = malloc(ws->cap * sizeof *ws->heap);
    if (ws->g && ws->h && ws->seen && ws->hseen && ws->goal && ws->heap) return 0;
    tcb_geo_ws_free(ws);
    return -1;
}

void tcb_geo_ws_next(tcb_geo_ws *ws)
{
    if (++ws->cur == 0) { /* wrapped: clear the stamps once */
        memset(ws->seen, 0, (size_t)ws->n * sizeof *ws->seen);
        memset(ws->hseen, 0, (size_t)ws->n * sizeof *ws->hseen);
        memset(ws->goal, 0, (size_t)ws->n * sizeof *ws->goal);
        ws->cur = 1;
    }
    ws->n_heap = 0;
}

/* A 4-ary min-heap on f: half the levels of a binary one, and a node's
 * children share a cache line (measured ~1.3x faster on the crane). */
#define ARITY 4

static int heap_push(tcb_geo_ws *ws, double f, int32_t v)
{
    if (ws->n_heap == ws->cap) {
        tcb_geo_heap_entry *grown = realloc(ws->heap, 2 * ws->cap * sizeof *grown);
        if (!grown) return -1;
        ws->heap = grown, ws->cap *= 2;
    }
    tcb_geo_heap_entry *h = ws->heap;
    size_t i = ws->n_heap++;
    while (i > 0 && f < h[(i - 1) / ARITY].f) {
        h[i] = h[(i - 1) / ARITY];
        i = (i - 1) / ARITY;
    }
    h[i] = (tcb_geo_heap_entry){f, v};
    return 0;
}

static tcb_geo_heap_entry heap_pop(tcb_geo_ws *ws)
{
    tcb_geo_heap_entry *h = ws->heap, top = h[0], x = h[--ws->n_heap];
    size_t n = ws->n_heap, i = 0;
    for (;;) {
        size_t c = ARITY * i + 1, best = c;
        if (c >= n) break;
        size_t end = c + ARITY < n ? c + ARITY : n;
        for (size_t k = c + 1; k < end; k++)
            if (h[k].f < h[best].f) best = k;
        if (!(h[best].f < x.f)) break;
        h[i] = h[best];
        i = best;
    }
    if (n) h[i] = x;
    return top;
}

/* The landmark bound max_l |d(l, t) − d(l, v)| (a triangle inequality per
 * landmark), less the slack that covers the rounding of those distances. */
static double landmark_bound(const tcb_geo_view *gv, int32_t v, int32_t t)
{
    const double *a = gv->lm + (size_t)v * TCB_GEO_LANDMARKS;
    const double *b = gv->lm + (size_t)t * TCB_GEO_LANDMARKS;
    double m = 0.0;
    /* max is exact in any order: vectorised. */
#pragma omp simd reduction(max : m)
    for (int l = 0; l < TCB_GEO_LANDMARKS; l++) {
        double d = fabs(a[l] - b[l]);
        m = d > m ? d : m;
    }
    return m - gv->lm_slack;
}

/* Lower bound of the distance from v to target (-1: none, Dijkstra),
 * computed once per vertex and search. */
static double heuristic(const tcb_geo_view *gv, tcb_geo_ws *ws, int32_t v, int32_t target)
{
    if (target < 0) return 0.0;
    if (ws->hseen[v] == ws->cur) return ws->h[v];
    const float *p = gv->verts + 3 * (size_t)v, *q = gv->verts + 3 * (size_t)target;
    double dx = (double)p[0] - q[0], dy = (double)p[1] - q[1], dz = (double)p[2] - q[2];
    double h = EUCLID_SHRINK * sqrt(dx * dx + dy * dy + dz * dz);
    if (gv->lm) h = fmax(h, landmark_bound(gv, v, target));
    ws->hseen[v] = ws->cur;
    return ws->h[v] = h;
}

/* Without a consistent heuristic a vertex may be expanded again when a
 * shorter path to it turns up later (there is no closed set): that keeps
 * the result exact whatever the rounding does to consistency. */
int tcb_geo_search(const tcb_geo_view *gv, tcb_geo_ws *ws, int32_t src, int m, int32_t target)
{
    const tcb_edge_graph *g = gv->g;
    ws->g[src] = 0.0;
    ws->seen[src] = ws->cur;
    if (heap_push(ws, heuristic(gv, ws, src, target), src)) return -1;
    while (ws->n_heap > 0) {
        tcb_geo_heap_entry top = heap_pop(ws);
        int32_t v = top.v;
        double gv_ = ws->g[v];
        /* Superseded by a shorter path (pushed again with a smaller f). An
         * entry within rounding of the current one may pass: expanding v
         * twice with its current g costs time, never exactness. */
        if (top.f > gv_ + heuristic(gv, ws, v, target)) continue;
        ws->expanded++;
        if (ws->goal[v] == ws->cur) {
            ws->goal[v] = 0;
            if (--m == 0) return 0;
        }
        for (int32_t e = g->offsets[v]; e < g->offsets[v + 1]; e++) {
            int32_t u = g->adj[e];
            double d = gv_ + gv->w[e];
            if (ws->seen[u] == ws->cur && d >= ws->g[u]) continue;
            ws->g[u] = d;
            ws->seen[u] = ws->cur;
            if (heap_push(ws, d + heuristic(gv, ws, u, target), u)) return -1;
        }
    }
    return m > 0 ? m : 0;
}
