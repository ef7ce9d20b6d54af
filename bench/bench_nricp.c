/* nricp registration throughput: pairs per second, as the `random`
 * strategy spends them (one Register call per evaluation pair).
 *
 * Workloads:
 *   synthetic  2500 of the synthetic quadruped's vertices (the TCSR input
 *              cloud size), the same subset in every frame
 *   cat        walking cat's 1297 GT vertices, when <data>/anim/cat_walk exists
 * Pairs (i, j) are drawn at random; they are registered in parallel, one
 * pair per thread (the way nricp's fit parallelizes its consecutive maps).
 *
 * usage: bench_nricp [data_dir] [pairs]   (data_dir defaults to ../shared/data) */
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_util.h"
#include "methods/nricp/register.h"
#include "tcb/geometry.h"
#include "tcb/progress.h"
#include "tcb/rng.h"
#include "tcb/sequence.h"
#include "tcb/synth.h"

#define CLOUD 2500

typedef struct workload {
    const char *name;
    int n_frames, n;
    float *pts, *nrm; /* [n_frames][n][3] */
} workload;

static void die(const char *what, const tcb_error *err)
{
    fprintf(stderr, "bench_nricp: %s: %s\n", what, err->msg);
    exit(1);
}

/* Points and vertex normals of the first n vertices of `keep` (NULL: all). */
static workload from_sequence(const char *name, const tcb_sequence *s, const int32_t *keep, int n)
{
    workload w = {name, s->n_frames, n, malloc((size_t)s->n_frames * n * 12),
                  malloc((size_t)s->n_frames * n * 12)};
    float *nrm = malloc((size_t)s->n_verts * 12);
    if (!w.pts || !w.nrm || !nrm) exit(1);
    for (int f = 0; f < s->n_frames; f++) {
        tcb_vertex_normals(tcb_seq_frame(s, f), s->n_verts, s->faces, s->n_faces, nrm);
        for (int v = 0; v < n; v++) {
            int src = keep ? keep[v] : v;
            memcpy(w.pts + ((size_t)f * n + v) * 3, tcb_seq_frame(s, f) + 3 * (size_t)src, 12);
            memcpy(w.nrm + ((size_t)f * n + v) * 3, nrm + 3 * (size_t)src, 12);
        }
    }
    free(nrm);
    return w;
}

static workload synthetic(void)
{
    tcb_sequence s;
    tcb_error err;
    if (tcb_synth_generate("quadruped_walk", 1, 0, &s, &err) ||
        tcb_sequence_normalize(&s, TCB_NORM_FIRST_FRAME, &err))
        die("synthetic", &err);
    int32_t *perm = malloc((size_t)s.n_verts * sizeof *perm);
    tcb_rng r;
    tcb_rng_seed_stream(&r, 1, "bench/nricp");
    tcb_rng_permutation(&r, perm, s.n_verts);
    workload w = from_sequence("synthetic", &s, perm, s.n_verts < CLOUD ? s.n_verts : CLOUD);
    free(perm);
    tcb_sequence_free(&s);
    return w;
}

static int cat(const char *data, workload *w)
{
    char dir[4096];
    snprintf(dir, sizeof dir, "%s/anim/cat_walk", data);
    tcb_load_opts o = {TCB_NORM_FIRST_FRAME, 100, 0, NULL, 0, NULL};
    tcb_sequence s;
    tcb_error err;
    if (tcb_sequence_load_objdir(dir, "cat_walk", &o, &s, &err)) return 0;
    *w = from_sequence("cat", &s, NULL, s.n_verts);
    tcb_sequence_free(&s);
    return 1;
}

/* Seconds to register `pairs` random pairs with `threads` threads. */
static double run(const workload *w, int pairs, int threads)
{
    tcb_rng r;
    tcb_rng_seed_stream(&r, 2, "bench/nricp/pairs");
    int *ij = malloc((size_t)pairs * 2 * sizeof *ij);
    for (int k = 0; k < pairs; k++) {
        ij[2 * k] = (int)tcb_rng_below(&r, (uint32_t)w->n_frames);
        ij[2 * k + 1] = (ij[2 * k] + 1 + (int)tcb_rng_below(&r, (uint32_t)w->n_frames - 1)) % w->n_frames;
    }
    nricp_params p = nricp_default_params();
    int failed = 0;
    /* Also the inner k-NN regions: with one outer thread they would
     * otherwise be active and spin up their own team. */
    omp_set_num_threads(threads);
    double t0 = tcb_now_seconds();
#pragma omp parallel num_threads(threads) reduction(| : failed)
    {
        float *out = malloc((size_t)w->n * 12);
        tcb_error err;
#pragma omp for schedule(dynamic, 1)
        for (int k = 0; k < pairs; k++) {
            size_t a = (size_t)ij[2 * k] * w->n * 3, b = (size_t)ij[2 * k + 1] * w->n * 3;
            failed |= nricp_register(w->pts + a, w->nrm + a, w->n, w->pts + b, w->nrm + b, w->n, &p, out,
                                     &err) != TCB_OK;
        }
        free(out);
    }
    double t = tcb_now_seconds() - t0;
    free(ij);
    if (failed) {
        fprintf(stderr, "bench_nricp: a registration failed\n");
        exit(1);
    }
    return t;
}

int main(int argc, char **argv)
{
    const char *data = argc > 1 ? argv[1] : "../shared/data";
    int pairs = argc > 2 ? bench_positive_int(argv[2], "pairs", "top of bench/bench_nricp.c") : 24;
    workload w[2];
    int nw = 0;
    w[nw++] = synthetic();
    if (cat(data, &w[nw])) nw++;
    else printf("(no %s/anim/cat_walk: synthetic workload only)\n", data);
    printf("nricp registration (rounds 25, smooth 3, smooth_last 1), %d random pairs\n", pairs);
    printf("%-10s %7s %8s %10s %10s\n", "workload", "points", "threads", "seconds", "pairs/s");
    for (int k = 0; k < nw; k++) {
        run(&w[k], 2, 1); /* warm-up: page in the code and the data */
        for (int threads = 1; threads <= 2; threads++) {
            double t = run(&w[k], pairs, threads);
            printf("%-10s %7d %8d %10.3f %10.2f\n", w[k].name, w[k].n, threads, t, pairs / t);
        }
        free(w[k].pts), free(w[k].nrm);
    }
    return 0;
}
