/* Training-pair sampling (reference-protocol §1.4, DatasetPairsBase): given
 * the first frame i, draw the second frame j ≠ i uniformly from a range R.
 * The authors draw from R and reject j == i up to 100 times; drawing directly
 * from R \ {i} gives the same distribution without the (i, i) fallback,
 * which only a one-frame R could reach. DFAUST's datasets concatenate the
 * subjects' blocks; the windows stay inside i's block, `random` does not. */
#include "tcb/split.h"

#include <string.h>

static const char *const mode_names[] = {"neighbors", "random", "within_seq", NULL};

int tcb_pair_mode_parse(const char *name, tcb_pair_mode *out)
{
    for (int m = 0; mode_names[m]; m++)
        if (name && strcmp(name, mode_names[m]) == 0) {
            *out = (tcb_pair_mode)m;
            return 0;
        }
    return -1;
}

/* j uniform over [lo, hi) \ {i}, where lo ≤ i < hi and hi − lo ≥ 2. */
static int draw_other(int lo, int hi, int i, tcb_rng *rng)
{
    int j = lo + (int)tcb_rng_below(rng, (uint32_t)(hi - lo - 1));
    return j >= i ? j + 1 : j;
}

/* Returns j, or −1 when no j exists: the caller's error to report. */
int tcb_pair_sample(tcb_pair_mode mode, int delta, int n_frames, int lo, int hi, int i, tcb_rng *rng)
{
    if (lo < 0 || hi > n_frames || i < lo || i >= hi || hi - lo < 2) return -1;
    switch (mode) {
    case TCB_PAIRS_NEIGHBORS: {
        if (delta < 1) return -1;
        /* R = [max(lo, i − δ), min(hi, i + δ + 1)), written to avoid overflow */
        int a = i - lo > delta ? i - delta : lo;
        int b = hi - i > delta ? i + delta + 1 : hi;
        return draw_other(a, b, i, rng);
    }
    /* as the authors' code: over the whole dataset, across blocks (subjects) */
    case TCB_PAIRS_RANDOM: return draw_other(0, n_frames, i, rng);
    case TCB_PAIRS_WITHIN_SEQ: return draw_other(lo, hi, i, rng);
    }
    return -1;
}
