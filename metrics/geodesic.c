/* Shortest-path distances on a frame's edge graph (tcb/geodesic.h): the
 * full Dijkstra field, and a pair's queries d(pred[k], k).
 *
 * A pair's queries are grouped by source (the predicted vertex). A source
 * with up to PER_TARGET_MAX queries answers each by an A* search towards
 * it; one with more (a method that maps many vertices to one) by a single
 * Dijkstra stopping once they are all settled, which then costs less than
 * that many A* searches.
 *
 * The A* bound is the straight-line distance, and, when the queries are
 * long, also the landmark (ALT) bound, which follows the surface. Building
 * the landmarks costs TCB_GEO_LANDMARKS full Dijkstras of the frame, which
 * short queries (a good method's) never repay, so the pair decides from
 * itself: a probe of PROBE_SOURCES sources spread over the list is answered
 * with the straight-line bound alone, and the landmarks are built only when
 * the vertices it expanded, extrapolated to the remaining sources, exceed
 * what the landmarks cost. The decision depends on the pair only, not on
 * timing or threads, so results are reproducible.
 *
 * Measured (bench/bench_geodesic.c, crane, random predictions): the landmarks
 * make a bad method's pair several times cheaper; a good method's pair
 * never builds them. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "metrics/geodesic_internal.h"

/* Sources answered one A* per query when they have at most this many. */
#define PER_TARGET_MAX 8
/* Sources answered before deciding on landmarks. */
#define PROBE_SOURCES 32
/* Below this many sources a pair stays single-threaded. */
#define PAR_MIN_SOURCES 64

int tcb_geodesic_field(const tcb_edge_graph *g, const double *w, int src, double *dist,
                       tcb_error *err)
{
    if (src < 0 || src >= g->n_verts)
        return tcb_fail(err, TCB_ERR_INPUT, "geodesic: source %d outside [0, %d)", src,
                        g->n_verts);
    tcb_geo_ws ws;
    if (tcb_geo_ws_init(&ws, g->n_verts))
        return tcb_fail(err, TCB_ERR_NOMEM, "geodesic: out of memory");
    tcb_geo_ws_next(&ws);
    tcb_geo_view gv = {g, w, NULL, NULL, 0.0};
    int rc = tcb_geo_search(&gv, &ws, src, 0, -1);
    for (int v = 0; rc == 0 && v < g->n_verts; v++)
        dist[v] = ws.seen[v] == ws.cur ? ws.g[v] : INFINITY;
    tcb_geo_ws_free(&ws);
    return rc ? tcb_fail(err, TCB_ERR_NOMEM, "geodesic: out of memory") : TCB_OK;
}

/* ---- a pair's queries, grouped by source ------------------------------ */

/* The vertices k predicted as s that need a search are
 * by_src[first[s] .. first[s + 1]). */
typedef struct query_groups {
    int32_t *first;    /* [n + 1] */
    int32_t *by_src;   /* [n] */
    int32_t *sources;  /* [n_sources] sources with at least one query, ascending */
    int n_sources;
} query_groups;

/* A vertex needs a search when its prediction is another vertex of its
 * own component; the others are final already (0, or the Euclidean
 * fallback). */
static int needs_search(const tcb_edge_graph *g, const int32_t *pred, int k)
{
    return pred[k] != k && g->component[pred[k]] == g->component[k];
}

/* A counting sort by source: counts, then starts, then each query placed
 * at its source's next slot (first[s] advancing to where s + 1 starts),
 * then the starts shifted back. */
static int group_queries(const tcb_edge_graph *g, const int32_t *pred, query_groups *q)
{
    int n = g->n_verts;
    q->first = calloc((size_t)n + 1, sizeof *q->first);
    q->by_src = malloc((size_t)n * sizeof *q->by_src);
    q->sources = malloc((size_t)n * sizeof *q->sources);
    if (!q->first || !q->by_src || !q->sources) return -1;
    for (int k = 0; k < n; k++)
        if (needs_search(g, pred, k)) q->first[pred[k] + 1]++;
    q->n_sources = 0;
    for (int s = 0; s < n; s++) {
        if (q->first[s + 1] > 0) q->sources[q->n_sources++] = s;
        q->first[s + 1] += q->first[s];
    }
    for (int k = 0; k < n; k++)
        if (needs_search(g, pred, k)) q->by_src[q->first[pred[k]]++] = k;
    for (int s = n; s > 0; s--) q->first[s] = q->first[s - 1];
    q->first[0] = 0;
    return 0;
}

static void groups_free(query_groups *q)
{
    free(q->first);
    free(q->by_src);
    free(q->sources);
}

/* Search from s for the goals t[0 .. m) (m = 1: A* towards t[0]), their
 * distances into dist. -1: out of memory; 1: a goal not reached (cannot
 * happen within a component). */
static int search_goals(const tcb_geo_view *gv, tcb_geo_ws *ws, int32_t s, const int32_t *t,
                        int m, double *dist)
{
    tcb_geo_ws_next(ws);
    for (int i = 0; i < m; i++) ws->goal[t[i]] = ws->cur;
    int left = tcb_geo_search(gv, ws, s, m, m == 1 ? t[0] : -1);
    if (left) return left < 0 ? -1 : 1;
    for (int i = 0; i < m; i++) dist[t[i]] = ws->g[t[i]];
    return 0;
}

static int answer_source(const tcb_geo_view *gv, tcb_geo_ws *ws, const query_groups *q,
                         int32_t s, double *dist)
{
    const int32_t *t = q->by_src + q->first[s];
    int m = q->first[s + 1] - q->first[s];
    if (m > PER_TARGET_MAX) return search_goals(gv, ws, s, t, m, dist);
    for (int i = 0; i < m; i++) {
        int rc = search_goals(gv, ws, s, t + i, 1, dist);
        if (rc) return rc;
    }
    return 0;
}

/* Is source index i one of the probe's (PROBE_SOURCES of them spread
 * evenly over the list, every source when there are fewer)? */
static int probed(int i, int n_sources)
{
    if (n_sources <= PROBE_SOURCES) return 1;
    /* i = floor(p · n / P) for some p: the first such i of each p. */
    long long p = ((long long)i * PROBE_SOURCES + n_sources - 1) / n_sources;
    return (long long)(p * n_sources / PROBE_SOURCES) == i;
}

/* Queries of source s that are A* searches (landmarks can speed them up);
 * a crowded source's are one Dijkstra, which they cannot. */
static int astar_queries(const query_groups *q, int32_t s)
{
    int m = q->first[s + 1] - q->first[s];
    return m <= PER_TARGET_MAX ? m : 0;
}

/* What the probe saw of the A* searches, and what is left of them. */
typedef struct probe_result {
    long long expanded;   /* vertices its A* searches expanded */
    int queries;          /* its A* queries */
    int queries_left;     /* A* queries of the sources it left */
} probe_result;

/* The probe, on this thread: its sources answered with the straight-line
 * bound. 0, or answer_source's error. */
static int run_probe(const tcb_geo_view *gv, const query_groups *q, double *dist,
                     probe_result *out)
{
    tcb_geo_ws ws;
    if (tcb_geo_ws_init(&ws, gv->g->n_verts)) return -1;
    int rc = 0;
    *out = (probe_result){0, 0, 0};
    for (int i = 0; i < q->n_sources && !rc; i++) {
        int32_t s = q->sources[i];
        if (!probed(i, q->n_sources)) {
            out->queries_left += astar_queries(q, s);
            continue;
        }
        long long before = ws.expanded;
        rc = answer_source(gv, &ws, q, s, dist);
        if (astar_queries(q, s)) out->expanded += ws.expanded - before;
        out->queries += astar_queries(q, s);
    }
    tcb_geo_ws_free(&ws);
    return rc;
}

/* The sources the probe left, spread over the threads; each query writes
 * only its own dist[k]. Returns 0, or 2 (out of memory) | 1 (unreached). */
static int answer_rest(const tcb_geo_view *gv, const query_groups *q, double *dist)
{
    int failed = 0;
#pragma omp parallel if (q->n_sources >= PAR_MIN_SOURCES) reduction(| : failed)
    {
        tcb_geo_ws ws;
        int ready = tcb_geo_ws_init(&ws, gv->g->n_verts) == 0;
#pragma omp for schedule(dynamic, 16)
        for (int i = 0; i < q->n_sources; i++) {
            if (probed(i, q->n_sources)) continue;
            int rc = ready && !failed ? answer_source(gv, &ws, q, q->sources[i], dist) : -1;
            if (rc) failed |= rc < 0 ? 2 : 1;
        }
        if (ready) tcb_geo_ws_free(&ws);
    }
    return failed;
}

/* Probe, decide on landmarks, answer the rest; 0, 2 (out of memory) or 1.
 * Landmarks are built when the A* searches left, at the probe's rate,
 * would expand more vertices than building them does (one full Dijkstra
 * per landmark). */
static int answer_all(tcb_geo_view *gv, const query_groups *q, double *dist)
{
    probe_result p;
    int rc = run_probe(gv, q, dist, &p);
    if (rc) return rc < 0 ? 2 : 1;
    if (q->n_sources <= PROBE_SOURCES) return 0;
    double *lm = NULL;
    double expected = p.queries ? (double)p.expanded * p.queries_left / p.queries : 0.0;
    if (expected > (double)TCB_GEO_LANDMARKS * gv->g->n_verts &&
        tcb_geo_landmarks(gv, &lm, &gv->lm_slack))
        return 2;
    gv->lm = lm;
    rc = answer_rest(gv, q, dist);
    gv->lm = NULL;
    free(lm);
    return rc;
}

int tcb_geodesic_to_pred(const tcb_edge_graph *g, const double *w, const float *verts,
                         const int32_t *pred, double *dist, int *n_unreachable, tcb_error *err)
{
    int n = g->n_verts, unreachable = 0;
    for (int k = 0; k < n; k++)
        if (pred[k] < 0 || pred[k] >= n)
            return tcb_fail(err, TCB_ERR_INPUT, "geodesic: pred[%d] = %d outside [0, %d)", k,
                            (int)pred[k], n);
    for (int k = 0; k < n; k++) {
        const float *p = verts + 3 * (size_t)pred[k], *v = verts + 3 * (size_t)k;
        int apart = g->component[pred[k]] != g->component[k];
        double dx = (double)p[0] - v[0], dy = (double)p[1] - v[1], dz = (double)p[2] - v[2];
        dist[k] = apart ? sqrt(dx * dx + dy * dy + dz * dz) : 0.0;
        unreachable += apart;
    }
    if (n_unreachable) *n_unreachable = unreachable;
    query_groups q = {0};
    tcb_geo_view gv = {g, w, verts, NULL, 0.0};
    int rc = group_queries(g, pred, &q) ? 2 : answer_all(&gv, &q, dist);
    groups_free(&q);
    if (rc & 2) return tcb_fail(err, TCB_ERR_NOMEM, "geodesic: out of memory");
    if (rc)
        return tcb_fail(err, TCB_ERR_INTERNAL,
                        "geodesic: a vertex of the source's component was not reached");
    return TCB_OK;
}
