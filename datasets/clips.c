/* Clip splits: the start frames of the 17-frame clips of the clip protocol
 * (DynoSurf's evaluation/eval_correspondences.py scores one 17-frame clip
 * per sequence; tcbench draws several per sequence, seeded, once, and keeps
 * them in a file as it keeps the pairs). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tcb/split.h"

static int cmp_start(const void *a, const void *b)
{
    int32_t x = *(const int32_t *)a, y = *(const int32_t *)b;
    return (x > y) - (x < y);
}

/* Every frame s whose clip [s, s + len) lies in one block, ascending, into
 * out[] (room for n_frames); returns how many. */
static int valid_starts(const tcb_block *blocks, int n_blocks, int n_frames, int len, int32_t *out)
{
    int n = 0;
    for (int s = 0; s + len <= n_frames; s++) {
        int lo, hi;
        tcb_block_find(blocks, n_blocks, n_frames, s, &lo, &hi);
        if (s + len <= hi) out[n++] = s;
    }
    return n;
}

/* The first `want` of a seeded partial Fisher-Yates shuffle of cand[0 .. n),
 * sorted: a uniform draw without replacement. */
static void draw_starts(const tcb_split *s, int32_t *cand, int n, int want)
{
    char label[256];
    snprintf(label, sizeof label, "clips/%s/%s", s->dataset, s->sequence);
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, s->seed, label);
    for (int k = 0; k < want; k++) {
        int r = k + (int)tcb_rng_below(&rng, (uint32_t)(n - k));
        int32_t t = cand[k];
        cand[k] = cand[r], cand[r] = t;
    }
    qsort(cand, (size_t)want, sizeof *cand, cmp_start);
}

int tcb_clips_make(const char *dataset, const char *sequence, tcb_role role, int n_frames,
                   const tcb_block *blocks, int n_blocks, int n_clips, uint64_t seed,
                   tcb_split *out, tcb_error *err)
{
    if (n_clips < 1)
        return tcb_fail(err, TCB_ERR_INPUT, "clips %s/%s: needs at least one clip, got %d", dataset,
                        sequence, n_clips);
    /* The header (names, blocks) as a pair split of no pairs checks it. */
    int rc = tcb_split_make(dataset, sequence, role, n_frames, blocks, n_blocks, 0, seed, out, err);
    if (rc) return rc;
    free(out->pairs);
    out->pairs = NULL;
    out->starts = malloc((size_t)n_frames * sizeof *out->starts);
    if (!out->starts) {
        tcb_split_free(out);
        return tcb_fail(err, TCB_ERR_NOMEM, "clips: out of memory");
    }
    int n = valid_starts(blocks, n_blocks, n_frames, TCB_CLIP_FRAMES, out->starts);
    if (n == 0) {
        tcb_split_free(out);
        return tcb_fail(err, TCB_ERR_INPUT,
                        "clips %s/%s: no %d consecutive frames in one block (the clip protocol needs "
                        "them; the sequence has %d frames%s)",
                        dataset, sequence, TCB_CLIP_FRAMES, n_frames, n_blocks ? " in blocks" : "");
    }
    out->clip_frames = TCB_CLIP_FRAMES;
    out->n_clips = n_clips < n ? n_clips : n;
    draw_starts(out, out->starts, n, out->n_clips);
    return TCB_OK;
}

int tcb_clips_obtain(const char *path, const char *dataset, const char *sequence, tcb_role role,
                     int n_frames, const tcb_block *blocks, int n_blocks, int n_clips,
                     uint64_t seed, tcb_split *out, tcb_error *err)
{
    int rc = tcb_clips_make(dataset, sequence, role, n_frames, blocks, n_blocks, n_clips, seed, out, err);
    return rc ? rc : tcb_split_obtain_made(path, out, err);
}
