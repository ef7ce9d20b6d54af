/* A clip folder's tracked points (datasets/clipdir.c, one pcl_seqs/NNNN.npy
 * frame), straight from the buffer: an accepted frame is (N, 3) finite
 * points, N the count asked for when one is; a refusal is one message. */
#include "fuzz/fuzz_util.h"
#include "tcb/sequence.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    for (int want = 0; want <= 2; want += 2) {
        float *pts = NULL;
        int n = 0;
        tcb_error err = {0};
        int rc = tcb_track_frame_parse(data, size, want, &pts, &n, &err);
        fuzz_check_point_frame(rc, &err, NULL, pts, n, want);
    }
    return 0;
}
