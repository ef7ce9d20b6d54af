/* Evaluation splits: the fixed list of (i, j) pairs every method of a
 * sequence is scored on (reference-protocol §5.2), drawn once from a seeded
 * stream and kept in a file so later runs and other methods reuse them. */
#include "tcb/split.h"

#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tcb/fsutil.h"

static const char *const role_names[] = {"train", "validation", "test", NULL};

const char *tcb_role_name(tcb_role role)
{
    return role >= TCB_ROLE_TRAIN && role <= TCB_ROLE_TEST ? role_names[role] : "unknown";
}

int tcb_role_parse(const char *name, tcb_role *out)
{
    for (int r = 0; role_names[r]; r++)
        if (name && strcmp(name, role_names[r]) == 0) {
            *out = (tcb_role)r;
            return 0;
        }
    return -1;
}

/* pairs[p] = (i, j): i uniform over all frames, j over the others of i's
 * block (§5.2; one block: the others of the sequence). */
static void draw_pairs(tcb_split *s)
{
    char label[256];
    snprintf(label, sizeof label, "split/%s/%s", s->dataset, s->sequence);
    tcb_rng rng;
    tcb_rng_seed_stream(&rng, s->seed, label);
    for (int p = 0; p < s->n_pairs; p++) {
        int lo, hi, i = (int)tcb_rng_below(&rng, (uint32_t)s->n_frames);
        tcb_block_find(s->blocks, s->n_blocks, s->n_frames, i, &lo, &hi);
        s->pairs[2 * p] = i;
        s->pairs[2 * p + 1] = tcb_pair_sample(TCB_PAIRS_WITHIN_SEQ, 0, s->n_frames, lo, hi, i, &rng);
    }
}

int tcb_split_make(const char *dataset, const char *sequence, tcb_role role, int n_frames,
                   const tcb_block *blocks, int n_blocks, int n_pairs, uint64_t seed,
                   tcb_split *out, tcb_error *err)
{
    memset(out, 0, sizeof *out);
    if (strlen(dataset) >= sizeof out->dataset || strlen(sequence) >= sizeof out->sequence)
        return tcb_fail(err, TCB_ERR_INPUT, "split %s/%s: name too long", dataset, sequence);
    if (n_frames < 2)
        return tcb_fail(err, TCB_ERR_INPUT, "split %s/%s: needs at least 2 frames, got %d",
                        dataset, sequence, n_frames);
    if (n_pairs < 0)
        return tcb_fail(err, TCB_ERR_INPUT, "split %s/%s: negative pair count %d", dataset,
                        sequence, n_pairs);
    char where[256];
    snprintf(where, sizeof where, "split %s/%s: blocks", dataset, sequence);
    int rc = tcb_blocks_check(blocks, n_blocks, n_frames, where, err);
    if (rc) return rc;
    out->pairs = malloc((size_t)(n_pairs > 0 ? n_pairs : 1) * 2 * sizeof(int32_t));
    out->blocks = n_blocks > 0 ? malloc((size_t)n_blocks * sizeof *blocks) : NULL;
    if (!out->pairs || (n_blocks > 0 && !out->blocks)) {
        tcb_split_free(out);
        return tcb_fail(err, TCB_ERR_NOMEM, "split: out of memory");
    }
    if (n_blocks > 0) memcpy(out->blocks, blocks, (size_t)n_blocks * sizeof *blocks);
    snprintf(out->dataset, sizeof out->dataset, "%s", dataset);
    snprintf(out->sequence, sizeof out->sequence, "%s", sequence);
    out->role = role, out->n_frames = n_frames, out->seed = seed, out->n_pairs = n_pairs;
    out->n_blocks = n_blocks;
    draw_pairs(out);
    return TCB_OK;
}

void tcb_split_free(tcb_split *s)
{
    free(s->pairs);
    free(s->blocks);
    free(s->starts);
    s->pairs = NULL;
    s->blocks = NULL;
    s->starts = NULL;
    s->n_pairs = 0;
    s->n_blocks = 0;
    s->n_clips = 0;
}

static void describe_count(int n_blocks, char *out, size_t size)
{
    if (n_blocks) snprintf(out, size, "%d blocks", n_blocks);
    else snprintf(out, size, "no blocks");
}

static void describe_block(const tcb_block *b, char *out, size_t size)
{
    snprintf(out, size, "\"%s\" frames [%d, %d)", b->name, b->start, b->start + b->n_frames);
}

/* The first block where s disagrees with the request, as disagreement(). */
static int block_disagreement(const tcb_split *s, const tcb_split *want, char *what, char *have,
                              char *wanted, size_t size)
{
    if (s->n_blocks != want->n_blocks) {
        snprintf(what, size, "blocks");
        describe_count(s->n_blocks, have, size), describe_count(want->n_blocks, wanted, size);
        return 1;
    }
    for (int k = 0; k < s->n_blocks; k++) {
        const tcb_block *a = &s->blocks[k], *b = &want->blocks[k];
        if (a->start == b->start && a->n_frames == b->n_frames && strcmp(a->name, b->name) == 0) continue;
        snprintf(what, size, "blocks[%d]", k);
        describe_block(a, have, size), describe_block(b, wanted, size);
        return 1;
    }
    return 0;
}

/* The first field where `s` disagrees with the request, written into what
 * (field name) and have/want (values), each of `size` bytes; 0 when
 * everything agrees. */
static int disagreement(const tcb_split *s, const tcb_split *want, char *what, char *have,
                        char *wanted, size_t size)
{
    if (strcmp(s->dataset, want->dataset) != 0) {
        snprintf(what, size, "dataset");
        snprintf(have, size, "\"%s\"", s->dataset), snprintf(wanted, size, "\"%s\"", want->dataset);
    } else if (strcmp(s->sequence, want->sequence) != 0) {
        snprintf(what, size, "sequence");
        snprintf(have, size, "\"%s\"", s->sequence);
        snprintf(wanted, size, "\"%s\"", want->sequence);
    } else if (s->role != want->role) {
        snprintf(what, size, "role");
        snprintf(have, size, "%s", tcb_role_name(s->role));
        snprintf(wanted, size, "%s", tcb_role_name(want->role));
    } else if (s->n_frames != want->n_frames) {
        snprintf(what, size, "n_frames");
        snprintf(have, size, "%d", s->n_frames), snprintf(wanted, size, "%d", want->n_frames);
    } else if (block_disagreement(s, want, what, have, wanted, size)) {
        return 1;
    } else if (s->n_pairs != want->n_pairs) {
        snprintf(what, size, "n_pairs");
        snprintf(have, size, "%d", s->n_pairs), snprintf(wanted, size, "%d", want->n_pairs);
    } else if (s->clip_frames != want->clip_frames) {
        snprintf(what, size, "clip_frames");
        snprintf(have, size, "%d", s->clip_frames), snprintf(wanted, size, "%d", want->clip_frames);
    } else if (s->n_clips != want->n_clips) {
        snprintf(what, size, "n_clips");
        snprintf(have, size, "%d", s->n_clips), snprintf(wanted, size, "%d", want->n_clips);
    } else if (s->seed != want->seed) {
        snprintf(what, size, "seed");
        snprintf(have, size, "%" PRIu64, s->seed), snprintf(wanted, size, "%" PRIu64, want->seed);
    } else {
        return 0;
    }
    return 1;
}

int tcb_split_obtain(const char *path, const char *dataset, const char *sequence,
                     tcb_role role, int n_frames, const tcb_block *blocks, int n_blocks,
                     int n_pairs, uint64_t seed, tcb_split *out, tcb_error *err)
{
    /* Making first also validates the request before any file is touched. */
    int rc = tcb_split_make(dataset, sequence, role, n_frames, blocks, n_blocks, n_pairs, seed, out, err);
    return rc ? rc : tcb_split_obtain_made(path, out, err);
}

int tcb_split_obtain_made(const char *path, tcb_split *out, tcb_error *err)
{
    int rc;
    if (!tcb_is_file(path)) {
        rc = tcb_split_save(path, out, err);
        if (rc) tcb_split_free(out);
        return rc;
    }
    tcb_split want = *out; /* keeps the requested blocks */
    free(out->pairs);
    free(out->starts);
    want.pairs = NULL, want.starts = NULL;
    rc = tcb_split_load(path, out, err);
    char what[160], have[160], wanted[160];
    if (!rc && disagreement(out, &want, what, have, wanted, sizeof have)) {
        tcb_split_free(out);
        rc = tcb_fail(err, TCB_ERR_INPUT,
                      "%s: %s is %s in the split file but %s is requested "
                      "(delete the file to draw a new split)",
                      path, what, have, wanted);
    }
    free(want.blocks);
    return rc;
}
