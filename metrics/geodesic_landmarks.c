/* Landmarks for the ALT bound of the geodesic searches: a frame's distance
 * to a few far-apart vertices. By the triangle inequality
 * |d(l, t) − d(l, v)| ≤ d(v, t) for every landmark l, so the largest such
 * difference bounds the distance left from v to t from below, and, unlike
 * the straight line, it follows the surface: on a body it knows that a
 * hand is far from the hip it hangs beside.
 *
 * The landmarks are spread by farthest-point sampling (each the vertex
 * farthest along the graph from those chosen) in the largest connected
 * component, starting from the vertex farthest from that component's
 * lowest vertex: deterministic, and at a body's extremities, where they
 * bound best. Other components get no landmark (their distances are 0, so
 * the bound is 0 there and the Euclidean one guides). */
#include <math.h>
#include <stdlib.h>

#include "metrics/geodesic_internal.h"

/* The component with the most vertices (the lowest id among equals) and
 * its lowest vertex. */
static int largest_component(const tcb_edge_graph *g, int *first_vertex)
{
    int *size = calloc((size_t)g->n_components, sizeof *size);
    if (!size) return -1;
    for (int v = 0; v < g->n_verts; v++) size[g->component[v]]++;
    int best = 0;
    for (int c = 1; c < g->n_components; c++)
        if (size[c] > size[best]) best = c;
    free(size);
    *first_vertex = 0;
    while (g->component[*first_vertex] != best) ++*first_vertex;
    return best;
}

/* A full Dijkstra from src into ws->g (valid where ws->seen[v] == ws->cur). */
static int field(const tcb_geo_view *gv, tcb_geo_ws *ws, int32_t src)
{
    tcb_geo_ws_next(ws);
    return tcb_geo_search(gv, ws, src, 0, -1) < 0 ? -1 : 0;
}

/* The reached vertex of the last field maximising key[] (the first among equals). */
static int32_t farthest(const tcb_geo_ws *ws, const double *key, int32_t start)
{
    int32_t best = start;
    for (int v = 0; v < ws->n; v++)
        if (ws->seen[v] == ws->cur && key[v] > key[best]) best = v;
    return best;
}

static int sample(const tcb_geo_view *gv, tcb_geo_ws *ws, double *lm, double *mind, double *dmax)
{
    int first;
    if (largest_component(gv->g, &first) < 0 || field(gv, ws, first)) return -1;
    int32_t at = farthest(ws, ws->g, first);
    for (int v = 0; v < ws->n; v++) mind[v] = INFINITY;
    for (int l = 0; l < TCB_GEO_LANDMARKS; l++) {
        if (field(gv, ws, at)) return -1;
        for (int v = 0; v < ws->n; v++) {
            if (ws->seen[v] != ws->cur) continue;
            lm[(size_t)v * TCB_GEO_LANDMARKS + l] = ws->g[v];
            mind[v] = fmin(mind[v], ws->g[v]);
            *dmax = fmax(*dmax, ws->g[v]);
        }
        at = farthest(ws, mind, at);
    }
    return 0;
}

int tcb_geo_landmarks(const tcb_geo_view *gv, double **out, double *slack)
{
    int n = gv->g->n_verts;
    tcb_geo_view plain = {gv->g, gv->w, gv->verts, NULL, 0.0};
    double *lm = calloc((size_t)n * TCB_GEO_LANDMARKS, sizeof *lm);
    double *mind = malloc((size_t)n * sizeof *mind), dmax = 0.0;
    tcb_geo_ws ws;
    int rc = !lm || !mind || tcb_geo_ws_init(&ws, n) ? -1 : 0;
    if (!rc) {
        rc = sample(&plain, &ws, lm, mind, &dmax);
        tcb_geo_ws_free(&ws);
    }
    free(mind);
    if (rc) {
        free(lm);
        return -1;
    }
    /* The distances are rounded sums, exact to ~1e-16 relative per edge:
     * 1e-9 of the largest keeps the bound below the true distance for
     * paths of up to ~1e6 edges. */
    *slack = 1e-9 * dmax;
    *out = lm;
    return 0;
}
