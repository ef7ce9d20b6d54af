/* tcbench — common evaluation splits and training-pair samplers.
 *
 * A split file is written once per sequence and then reused, so every method
 * is scored on the identical 500 pairs (i, j), i ≠ j (reference-protocol
 * §5.2; the authors drew fresh unseeded pairs per run, we fix them). For a
 * sequence of several blocks (DFAUST subjects, tcb/block.h) i is uniform
 * over all frames and j over the other frames of i's block, and the split
 * records the blocks. */
#ifndef TCB_SPLIT_H
#define TCB_SPLIT_H

#include <stdint.h>

#include "tcb/block.h"
#include "tcb/error.h"
#include "tcb/rng.h"

#ifdef __cplusplus
extern "C" {
#endif

#define TCB_DEFAULT_EVAL_PAIRS 500

typedef enum tcb_role { TCB_ROLE_TRAIN, TCB_ROLE_VALIDATION, TCB_ROLE_TEST } tcb_role;

const char *tcb_role_name(tcb_role role);
int tcb_role_parse(const char *name, tcb_role *out); /* 0 on success, -1 unknown */

typedef struct tcb_split {
    char dataset[64];
    char sequence[128];
    tcb_role role;
    int n_frames;
    int n_blocks;      /* 0: one block, all frames (the file has no "blocks") */
    tcb_block *blocks; /* [n_blocks] */
    uint64_t seed;
    int n_pairs;
    int32_t *pairs; /* [n_pairs][2]: i uniform over frames, j uniform over the others of i's block */
    /* A clip split (tcb_clips_make) when clip_frames > 0, with no pairs:
     * n_clips clips of clip_frames consecutive frames, clip c the frames
     * starts[c] .. starts[c] + clip_frames - 1, all in one block; starts
     * ascending and distinct. 0, 0, NULL in a pair split. */
    int clip_frames;
    int n_clips;
    int32_t *starts;
} tcb_split;

/* blocks[0..n_blocks) as the sequence's (tcb_blocks_check); NULL, 0 for
 * one block. */
int tcb_split_make(const char *dataset, const char *sequence, tcb_role role, int n_frames,
                   const tcb_block *blocks, int n_blocks, int n_pairs, uint64_t seed,
                   tcb_split *out, tcb_error *err);
/* Either kind of split (a clip split when clip_frames > 0): JSON, atomic;
 * load takes either file format. */
int tcb_split_save(const char *path, const tcb_split *s, tcb_error *err);
int tcb_split_load(const char *path, tcb_split *out, tcb_error *err);
/* The split as its file's JSON text (the tree tcb_split_save writes,
 * unindented); malloc'ed, NULL when out of memory. */
char *tcb_split_json(const tcb_split *s);
/* Load `path` if it exists and agrees with the request (dataset, sequence,
 * role, n_frames, blocks, n_pairs, seed), else make and save it.
 * Disagreement is an error (TCB_ERR_INPUT) naming the file and the first
 * differing field; the pairs of an existing file are used as stored. */
int tcb_split_obtain(const char *path, const char *dataset, const char *sequence,
                     tcb_role role, int n_frames, const tcb_block *blocks, int n_blocks,
                     int n_pairs, uint64_t seed, tcb_split *out, tcb_error *err);
void tcb_split_free(tcb_split *s);
/* The common part of tcb_split_obtain and tcb_clips_obtain: *made is the
 * split the request makes (freed on failure); the file at path, when it
 * exists, replaces it if it agrees with it in every field but the pairs
 * or starts, else the disagreement is the error. */
int tcb_split_obtain_made(const char *path, tcb_split *made, tcb_error *err);

/* The clip protocol of DynoSurf, PDG and Neu-PiG (docs/protocol.md, "The
 * clip protocol"): 17 consecutive frames, frame 0 transferred to frames
 * 1-16. A clip split file <splits_dir>/<dataset>/<sequence>.clips.json,
 * format "tcbench-clips/1", holds the start frames, drawn once like the
 * pairs. */
#define TCB_CLIP_FRAMES 17
#define TCB_DEFAULT_EVAL_CLIPS 10

/* n_clips distinct start frames s drawn uniformly, without replacement, from
 * those whose clip [s, s + TCB_CLIP_FRAMES) lies in one block (seeded stream
 * "clips/<dataset>/<sequence>"), sorted; all of them when there are fewer
 * (out->n_clips says how many). A sequence with no such clip is an error
 * (TCB_ERR_INPUT). */
int tcb_clips_make(const char *dataset, const char *sequence, tcb_role role, int n_frames,
                   const tcb_block *blocks, int n_blocks, int n_clips, uint64_t seed,
                   tcb_split *out, tcb_error *err);
/* tcb_split_obtain for a clip split: load `path` if it agrees with the
 * request (dataset, sequence, role, n_frames, blocks, clip_frames,
 * n_clips, seed), else make and save it. */
int tcb_clips_obtain(const char *path, const char *dataset, const char *sequence, tcb_role role,
                     int n_frames, const tcb_block *blocks, int n_blocks, int n_clips,
                     uint64_t seed, tcb_split *out, tcb_error *err);

/* Training-pair sampling (§1.4): given i in its block [lo, hi) of a
 * sequence of n_frames frames (tcb_seq_block_of; [0, n_frames) without
 * blocks), draw j ≠ i.
 *   NEIGHBORS:  1 ≤ |i − j| ≤ delta, clipped to the block [lo, hi)
 *   RANDOM:     uniform over the other frames of the whole sequence, across
 *               blocks (subjects), as the authors' code does
 *   WITHIN_SEQ: uniform over the other frames of the block
 * Returns −1 when no j exists (a block of fewer than 2 frames, [lo, hi) not
 * inside [0, n_frames), i outside [lo, hi), or delta < 1 for NEIGHBORS):
 * the caller reports it. */
typedef enum tcb_pair_mode { TCB_PAIRS_NEIGHBORS, TCB_PAIRS_RANDOM, TCB_PAIRS_WITHIN_SEQ } tcb_pair_mode;

int tcb_pair_mode_parse(const char *name, tcb_pair_mode *out); /* 0 ok, -1 unknown */
int tcb_pair_sample(tcb_pair_mode mode, int delta, int n_frames, int lo, int hi, int i, tcb_rng *rng);

#ifdef __cplusplus
}
#endif
#endif
