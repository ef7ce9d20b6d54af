/* tcbench — blocks: consecutive frame ranges of one sequence.
 *
 * A DFAUST sequence (reference-protocol §1.1) is every subject that
 * performed it, one block of frames per subject; a pair of frames compared
 * in evaluation, or sampled by a window in training, stays inside one block
 * (§1.4, §5.2). Every other source has no blocks (n == 0), which means one
 * unnamed block over the whole sequence. */
#ifndef TCB_BLOCK_H
#define TCB_BLOCK_H

#include "tcb/error.h"

#ifdef __cplusplus
extern "C" {
#endif

#define TCB_BLOCK_NAME_MAX 64

typedef struct tcb_block {
    char name[TCB_BLOCK_NAME_MAX]; /* DFAUST: the subject id, e.g. "50002" */
    int start;                     /* first frame */
    int n_frames;
} tcb_block;

/* The block holding frame f among b[0..n), which tile [0, n_frames) in
 * order (tcb_blocks_check): returns its index and its frames [*lo, *hi).
 * With n == 0 the whole sequence is block 0. Returns −1 (and [0, n_frames))
 * when f is outside [0, n_frames). */
static inline int tcb_block_find(const tcb_block *b, int n, int n_frames, int f, int *lo, int *hi)
{
    *lo = 0, *hi = n_frames;
    if (f < 0 || f >= n_frames) return -1;
    for (int k = 0; k < n; k++)
        if (f < b[k].start + b[k].n_frames) {
            *lo = b[k].start, *hi = b[k].start + b[k].n_frames;
            return k;
        }
    return n ? -1 : 0;
}

/* Fails (TCB_ERR_INPUT, "<where>[k]: ...") unless the blocks tile
 * [0, n_frames) in order, each with at least 2 frames (a pair needs two) and
 * a non-empty name distinct from the others. n == 0 always passes. */
int tcb_blocks_check(const tcb_block *b, int n, int n_frames, const char *where, tcb_error *err);

#ifdef __cplusplus
}
#endif
#endif
