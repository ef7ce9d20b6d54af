/* One frame of Occupancy Flow's point-cloud sequences (datasets/pcl_seq.c):
 * an .npz whose points, loc and scale give world coordinates; what is
 * accepted is finite points, as many as asked for when a count is. */
#include "fuzz/fuzz_util.h"
#include "tcb/sequence.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *path = fuzz_file("frame.npz", data, size);
    for (int want = 0; want <= 3; want += 3) {
        float *pts = NULL;
        int n = 0;
        tcb_error err = {0};
        int rc = tcb_pcl_seq_frame_read(path, want, &pts, &n, &err);
        fuzz_check_point_frame(rc, &err, path, pts, n, want);
    }
    return 0;
}
