/* propagate_deform's evaluation: one chain per (source, direction) with
 * the pairs' shared prefixes (prepare_pairs, methods/nricp/deform.c)
 * against its peer, one chain per pair (transfer alone, as before), on the
 * same pairs, through the method table as the harness calls it. Prints
 * registrations, seconds and the ratios, and checks that both give the
 * same bits.
 *
 * Workload: the first `frames` frames of an OBJ sequence's GT vertices
 * (default the walking cat, 1297 vertices; AMA's crane has 10 002), else
 * of the synthetic quadruped; `pairs` pairs drawn as a split draws them.
 * The defaults keep crane's density of evaluation pairs (500 over 175
 * frames), on which the sharing depends.
 *
 * usage: bench_nricp_deform [sequence_dir [frames [pairs]]]
 *        (../shared/data/anim/cat_walk, 40, 114) */
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_util.h"
#include "methods/nricp/deform_cost.h"
#include "tcb/progress.h"
#include "tcb/registry.h"
#include "tcb/split.h"
#include "tcb/synth.h"

#define PROG "bench_nricp_deform"

static void load(const char *dir, int frames, tcb_sequence *s, const char **name)
{
    tcb_load_opts o = {TCB_NORM_PER_FRAME, 100, 0, NULL, 0, NULL};
    tcb_error err;
    const char *slash = strrchr(dir, '/');
    *name = slash && slash[1] ? slash + 1 : dir;
    if (tcb_sequence_load_objdir(dir, *name, &o, s, &err)) {
        printf("(%s: the synthetic quadruped instead)\n", err.msg);
        *name = "quadruped_walk";
        if (tcb_synth_generate("quadruped_walk", 1, 0, s, &err)) bench_die(PROG, "synthetic: %s", err.msg);
    }
    if (frames > s->n_frames) bench_die(PROG, "%s has %d frames, fewer than %d", *name, s->n_frames, frames);
    s->n_frames = frames; /* the first frames: the arrays are frame-major */
}

static void count_steps(void *ctx, double done, double total, const char *label)
{
    (void)done, (void)label;
    *(double *)ctx = total;
}

static void *fitted(const tcb_sequence *s, int threads)
{
    const tcb_method_ops *ops = tcb_registry_find("nricp");
    void *self;
    tcb_error err;
    tcb_fit_ctx ctx = {.seed = 1, .n_threads = threads};
    if (ops->create("{\"strategy\": \"propagate_deform\"}", &self, &err) || ops->fit(self, s, &ctx, &err))
        bench_die(PROG, "fit: %s", err.msg);
    return self;
}

/* Seconds to transfer every pair into out ([n][n_verts][3]); with
 * `threads` > 0 the pairs are announced first (that many threads), and
 * *steps gets the registrations the chains took. */
static double evaluate(const tcb_sequence *s, const tcb_split *sp, int threads, float *out, double *steps)
{
    const tcb_method_ops *ops = tcb_registry_find("nricp");
    void *self = fitted(s, 1);
    tcb_error err;
    tcb_rng rng;
    tcb_rng_seed(&rng, 1);
    size_t frame = (size_t)s->n_verts * 3;
    /* The registration's inner k-NN regions too, as the harness sets it
     * for a cell: left at the machine's count they spin up a team per call. */
    omp_set_num_threads(threads > 0 ? threads : 1);
    double t0 = tcb_now_seconds();
    if (threads > 0) {
        tcb_fit_ctx ctx = {.seed = 1, .n_threads = threads, .reporter = {count_steps, NULL, steps}};
        if (ops->prepare_pairs(self, s, sp->pairs, 0, sp->n_pairs, &ctx, &err))
            bench_die(PROG, "prepare_pairs: %s", err.msg);
    }
    for (int p = 0; p < sp->n_pairs; p++) {
        int i = sp->pairs[2 * p], j = sp->pairs[2 * p + 1];
        if (ops->transfer(self, s, i, j, tcb_seq_frame(s, i), s->n_verts, out + p * frame, &rng, &err))
            bench_die(PROG, "transfer %d->%d: %s", i, j, err.msg);
    }
    double t = tcb_now_seconds() - t0;
    ops->destroy(self);
    return t;
}

int main(int argc, char **argv)
{
    const char *dir = argc > 1 ? argv[1] : "../shared/data/anim/cat_walk";
    int frames = argc > 2 ? bench_positive_int(argv[2], "frames", "top of bench/nricp_deform.c") : 40;
    int pairs = argc > 3 ? bench_positive_int(argv[3], "pairs", "top of bench/nricp_deform.c") : 114;
    tcb_sequence s;
    const char *name;
    load(dir, frames, &s, &name);
    tcb_split sp;
    tcb_error err;
    if (tcb_split_make("bench", name, TCB_ROLE_VALIDATION, s.n_frames, NULL, 0, pairs, 2021, &sp, &err))
        bench_die(PROG, "split: %s", err.msg);
    double per_pair_steps = 0;
    for (int p = 0; p < pairs; p++) per_pair_steps += abs(sp.pairs[2 * p] - sp.pairs[2 * p + 1]);

    size_t bytes = (size_t)pairs * s.n_verts * 3 * sizeof(float);
    float *lone = malloc(bytes), *batch = malloc(bytes);
    if (!lone || !batch) bench_die(PROG, "out of memory for %d pairs", pairs);
    printf("nricp propagate_deform, %s: %d frames of %d vertices, %d pairs\n", name, s.n_frames, s.n_verts,
           pairs);
    printf("%-26s %8s %13s %10s %9s\n", "evaluation", "threads", "registrations", "seconds", "speed-up");
    double t_lone = evaluate(&s, &sp, 0, lone, NULL);
    printf("%-26s %8d %13.0f %10.2f %9s\n", "one chain per pair (peer)", 1, per_pair_steps, t_lone, "1.00");
    for (int threads = 1; threads <= 2; threads++) {
        double steps = 0, t = evaluate(&s, &sp, threads, batch, &steps);
        printf("%-26s %8d %13.0f %10.2f %9.2f\n", "shared chains", threads, steps, t, t_lone / t);
        if (memcmp(lone, batch, bytes) != 0) bench_die(PROG, "the shared chains differ from the peer's");
    }
    printf("shared chains' registrations expected for uniform pairs (the dry run's estimate): %.0f\n",
           nricp_deform_expected_steps(s.n_frames, pairs));
    free(lone), free(batch);
    tcb_split_free(&sp);
    tcb_sequence_free(&s);
    return 0;
}
