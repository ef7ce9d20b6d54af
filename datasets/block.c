/* Validation of a sequence's blocks (tcb/block.h): whatever reads them from
 * a file (split, cache) or builds them (DFAUST) checks them here once, so
 * tcb_block_find can trust the tiling. */
#include "tcb/block.h"

#include <string.h>

int tcb_blocks_check(const tcb_block *b, int n, int n_frames, const char *where, tcb_error *err)
{
    int end = 0;
    for (int k = 0; k < n; k++) {
        if (!memchr(b[k].name, '\0', sizeof b[k].name) || !b[k].name[0])
            return tcb_fail(err, TCB_ERR_INPUT, "%s[%d].name: must be 1 to %d characters", where, k,
                            TCB_BLOCK_NAME_MAX - 1);
        if (b[k].start != end)
            return tcb_fail(err, TCB_ERR_INPUT, "%s[%d].start: %d, expected %d (blocks are consecutive)",
                            where, k, b[k].start, end);
        if (b[k].n_frames < 2 || b[k].n_frames > n_frames - end)
            return tcb_fail(err, TCB_ERR_INPUT, "%s[%d].n_frames: %d, expected 2 to %d frames", where, k,
                            b[k].n_frames, n_frames - end);
        for (int m = 0; m < k; m++)
            if (strcmp(b[m].name, b[k].name) == 0)
                return tcb_fail(err, TCB_ERR_INPUT, "%s[%d].name: \"%s\" repeats %s[%d]", where, k, b[k].name,
                                where, m);
        end += b[k].n_frames;
    }
    if (n > 0 && end != n_frames)
        return tcb_fail(err, TCB_ERR_INPUT, "%s: the blocks cover %d frames of %d", where, end, n_frames);
    return TCB_OK;
}
