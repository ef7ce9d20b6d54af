/* Cost of one pair's geodesic error (tcb_pair_geodesic_compute) beside
 * its peer, a plain full Dijkstra from every source the pair needs
 * (tcb_geodesic_field, read off at the targets), measured in the same run
 * on the same queries; the distances must agree.
 *
 * Meshes: crane-sized (10 002 vertices: the real AMA crane, frames 0 and
 * 50, when <data_dir>/ama/crane is there, else a synthetic one) and
 * DFAUST-sized (6 890 vertices, synthetic). The synthetic mesh is a long
 * ellipsoid bent into a U, a body-like worst case for the Euclidean
 * heuristic (the arms are close in space, far along the surface); its
 * frames are the U bent to 0.8π and π. Two predictions per mesh:
 *   nearest  each vertex of frame i to its nearest vertex of frame j (the
 *            `nearest` baseline: a good method's small errors);
 *   random   uniform random vertices (a bad method: long paths everywhere).
 * For context the Euclidean metrics' time (tcb_pair_metrics_compute) of the
 * same pair. Ours is the best of `reps` runs, the peer is run once.
 *
 * usage: bench_geodesic [data_dir] [reps]   (data_dir defaults to ../shared/data;
 *                                            threads: OMP_NUM_THREADS) */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_util.h"
#include "tests/support/bent_tube.h"
#include "tcb/geodesic.h"
#include "tcb/geometry.h"
#include "tcb/mesh_io.h"
#include "tcb/nn.h"
#include "tcb/rng.h"

#define PROG "bench_geodesic"

typedef struct frames {
    char name[64];
    int nv, nf;
    float *vi, *vj;  /* [nv][3] frames i and j */
    int32_t *faces;  /* [nf][3] */
} frames;

/* ---- the synthetic U ----------------------------------------------- */

/* 2 poles + rings × segs vertices, length 8, radius 1 (tests/support/
 * bent_tube.h); frame i bent to 0.8π, frame j to π; both share the faces. */
static void synth_u(frames *f, int rings, int segs)
{
    f->nv = bent_tube_verts(rings, segs);
    f->nf = bent_tube_faces(rings, segs);
    f->vi = malloc((size_t)f->nv * 3 * sizeof(float));
    f->vj = malloc((size_t)f->nv * 3 * sizeof(float));
    f->faces = malloc((size_t)f->nf * 3 * sizeof(int32_t));
    if (!f->vi || !f->vj || !f->faces) bench_die(PROG, "out of memory");
    bent_tube(rings, segs, 8.0, 0.8 * M_PI, 0.0, 1, f->vi, f->faces);
    bent_tube(rings, segs, 8.0, M_PI, 0.0, 1, f->vj, f->faces);
}

/* ---- the real crane ------------------------------------------------- */

static int read_crane(const char *data_dir, frames *f)
{
    char pi[1024], pj[1024];
    snprintf(pi, sizeof pi, "%s/ama/crane/mesh_0000.obj", data_dir);
    snprintf(pj, sizeof pj, "%s/ama/crane/mesh_0010.obj", data_dir);
    tcb_mesh a, b;
    tcb_error err = {0};
    if (tcb_obj_read(pi, &a, &err)) return 0;
    if (tcb_obj_read(pj, &b, &err) || b.n_verts != a.n_verts) {
        tcb_mesh_free(&a);
        return 0;
    }
    snprintf(f->name, sizeof f->name, "crane (AMA)");
    f->nv = a.n_verts, f->nf = a.n_faces;
    f->vi = a.verts, f->faces = a.faces, f->vj = b.verts;
    free(b.faces);
    return 1;
}

/* ---- predictions ---------------------------------------------------- */

/* Frame i's vertices projected to frame j's, both centred on their vertex
 * centroid first (as the harness's normalisation would). */
static void predict_nearest(const frames *f, int32_t *pred)
{
    float *ci = malloc((size_t)f->nv * 3 * sizeof(float)), *cj = malloc((size_t)f->nv * 3 * sizeof(float));
    if (!ci || !cj) bench_die(PROG, "out of memory");
    for (int fr = 0; fr < 2; fr++) {
        const float *v = fr ? f->vj : f->vi;
        float *c = fr ? cj : ci;
        double m[3] = {0, 0, 0};
        for (int k = 0; k < f->nv; k++)
            for (int a = 0; a < 3; a++) m[a] += v[3 * k + a];
        for (int k = 0; k < f->nv; k++)
            for (int a = 0; a < 3; a++) c[3 * k + a] = (float)(v[3 * k + a] - m[a] / f->nv);
    }
    tcb_error err = {0};
    if (tcb_nn_nearest(cj, f->nv, ci, f->nv, pred, NULL, &err)) bench_die(PROG, "%s", err.msg);
    free(ci), free(cj);
}

static void predict_random(int nv, int32_t *pred)
{
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, 1, "bench/geodesic");
    for (int k = 0; k < nv; k++) pred[k] = (int32_t)tcb_rng_below(&rng, (uint64_t)nv);
}

/* ---- timing --------------------------------------------------------- */

static double time_ours(const tcb_edge_graph *g, const frames *f, double area, const int32_t *pred,
                        int reps, double *verr)
{
    double best = 1e300;
    for (int r = 0; r < reps; r++) {
        tcb_pair_metrics m = {0};
        tcb_error err = {0};
        double t0 = bench_now_ms();
        if (tcb_pair_geodesic_compute(g, f->vj, area, pred, &m, verr, &err)) bench_die(PROG, "%s", err.msg);
        double t = bench_now_ms() - t0;
        if (t < best) best = t;
    }
    return best;
}

/* The peer: a full Dijkstra field from each distinct source, d(pred[k], k)
 * read off it; normalised as ours. Returns ms, *n_src the sources. */
static double time_peer(const tcb_edge_graph *g, const frames *f, double area, const int32_t *pred,
                        double *verr, int *n_src)
{
    int nv = f->nv;
    double *w = malloc(((size_t)2 * g->n_edges + 1) * sizeof *w), *field = malloc((size_t)nv * sizeof *field);
    int32_t *first = calloc((size_t)nv + 1, sizeof *first), *order = malloc((size_t)nv * sizeof *order);
    if (!w || !field || !first || !order) bench_die(PROG, "out of memory");
    double t0 = bench_now_ms();
    tcb_edge_graph_lengths(g, f->vj, w);
    for (int k = 0; k < nv; k++) first[pred[k] + 1]++;
    for (int s = 0; s < nv; s++) first[s + 1] += first[s];
    for (int k = 0; k < nv; k++) order[first[pred[k]]++] = k;
    *n_src = 0;
    tcb_error err = {0};
    for (int s = 0, at = 0; s < nv; s++) {
        int end = first[s];
        int needed = 0;
        for (int i = at; i < end; i++) needed |= order[i] != s;
        if (needed) {
            if (tcb_geodesic_field(g, w, s, field, &err)) bench_die(PROG, "%s", err.msg);
            ++*n_src;
        }
        for (int i = at; i < end; i++) verr[order[i]] = (order[i] == s ? 0.0 : field[order[i]]) / sqrt(area);
        at = end;
    }
    double t = bench_now_ms() - t0;
    free(w), free(field), free(first), free(order);
    return t;
}

static double time_euclidean(const frames *f, const int32_t *pred, int reps)
{
    double best = 1e300;
    for (int r = 0; r < reps; r++) {
        tcb_pair_metrics m;
        tcb_error err = {0};
        double t0 = bench_now_ms();
        if (tcb_pair_metrics_compute(f->vj, f->nv, pred, &m, &err)) bench_die(PROG, "%s", err.msg);
        double t = bench_now_ms() - t0;
        if (t < best) best = t;
    }
    return best;
}

static void run_mesh(const frames *f, int reps)
{
    tcb_edge_graph g;
    tcb_error err = {0};
    if (tcb_edge_graph_build(f->faces, f->nf, f->nv, &g, &err)) bench_die(PROG, "%s", err.msg);
    double area = tcb_mesh_area(f->vj, f->faces, f->nf);
    int32_t *pred = malloc((size_t)f->nv * sizeof *pred);
    double *ours = malloc((size_t)f->nv * sizeof *ours), *peer = malloc((size_t)f->nv * sizeof *peer);
    if (!pred || !ours || !peer) bench_die(PROG, "out of memory");
    for (int p = 0; p < 2; p++) {
        if (p == 0) predict_nearest(f, pred);
        else predict_random(f->nv, pred);
        int wrong = 0;
        for (int k = 0; k < f->nv; k++) wrong += pred[k] != k;
        double t_ours = time_ours(&g, f, area, pred, reps, ours);
        int n_src;
        double t_peer = time_peer(&g, f, area, pred, peer, &n_src);
        double t_euc = time_euclidean(f, pred, reps), worst = 0, mean = 0;
        for (int k = 0; k < f->nv; k++) {
            worst = fmax(worst, fabs(ours[k] - peer[k]) / fmax(peer[k], 1e-300));
            mean += ours[k] / f->nv;
        }
        if (worst > 1e-12) bench_die(PROG, "%s: ours and the peer differ by %.1e", f->name, worst);
        printf("%-14s %6d %-8s %7d %7d %7.4f %10.2f %12.1f %8.1f %10.2f\n", f->name, f->nv,
               p ? "random" : "nearest", wrong, n_src, mean, t_ours, t_peer, t_peer / t_ours, t_euc);
    }
    free(pred), free(ours), free(peer);
    tcb_edge_graph_free(&g);
}

int main(int argc, char **argv)
{
    const char *data = argc > 1 ? argv[1] : "../shared/data";
    int reps = argc > 2 ? bench_positive_int(argv[2], "reps", "top of bench/bench_geodesic.c") : 3;
    frames meshes[2];
    memset(meshes, 0, sizeof meshes);
    if (!read_crane(data, &meshes[0])) {
        snprintf(meshes[0].name, sizeof meshes[0].name, "U-shape");
        synth_u(&meshes[0], 100, 100);
        printf("(%s/ama/crane not found: a synthetic crane-sized mesh)\n", data);
    }
    snprintf(meshes[1].name, sizeof meshes[1].name, "U-shape");
    synth_u(&meshes[1], 82, 84);
    printf("geodesic error of one pair, ours best of %d, peer (full Dijkstra per source) once, %d thread(s)\n",
           reps, omp_get_max_threads());
    printf("%-14s %6s %-8s %7s %7s %7s %10s %12s %8s %10s\n", "mesh", "K", "pred", "wrong", "sources",
           "m_geo", "ours ms", "peer ms", "peer/ours", "eucl. ms");
    for (int m = 0; m < 2; m++) {
        run_mesh(&meshes[m], reps);
        free(meshes[m].vi), free(meshes[m].vj), free(meshes[m].faces);
    }
    return 0;
}
