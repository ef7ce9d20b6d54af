/* The split file reader (datasets/split_io.c): a split read has its pairs
 * inside the frames, i != j, and j in i's block. */
#include "fuzz/fuzz_util.h"
#include "tcb/split.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *path = fuzz_file("split.json", data, size);
    tcb_split s;
    tcb_error err = {0};
    int rc = tcb_split_load(path, &s, &err);
    fuzz_check_answer(rc, &err, path);
    if (rc) return 0;
    for (int p = 0; p < s.n_pairs; p++) {
        int i = s.pairs[2 * p], j = s.pairs[2 * p + 1];
        fuzz_require(i >= 0 && i < s.n_frames && j >= 0 && j < s.n_frames && i != j, "pairs of two frames");
        int lo = 0, hi = s.n_frames;
        for (int b = 0; b < s.n_blocks; b++)
            if (i >= s.blocks[b].start && i < s.blocks[b].start + s.blocks[b].n_frames)
                lo = s.blocks[b].start, hi = lo + s.blocks[b].n_frames;
        fuzz_require(j >= lo && j < hi, "j in i's block");
    }
    tcb_split_free(&s);
    return 0;
}
