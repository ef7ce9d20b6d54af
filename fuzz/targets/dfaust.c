/* The DFAUST registrations reader (datasets/dfaust.c), structure-aware
 * (see fuzz/h5_program.h): the program builds registrations_m.hdf5 and
 * the sequence "jumping" is read for every subject found and for the
 * listed 50002; what is read has faces within its vertices and finite
 * coordinates. */
#include <math.h>

#include "fuzz/fuzz_util.h"
#include "fuzz/h5_names.h"
#include "fuzz/h5_program.h"
#include "tcb/dfaust.h"

static void read_and_check(char *const *subjects, int n)
{
    const char *root = fuzz_dir();
    tcb_sequence s;
    tcb_error err = {0};
    int rc = tcb_dfaust_read(root, "jumping", subjects, n, &s, &err);
    fuzz_check_answer(rc, &err, NULL);
    if (rc) return;
    for (size_t k = 0; k < 3 * (size_t)s.n_faces; k++)
        fuzz_require(s.faces[k] >= 0 && s.faces[k] < s.n_verts, "faces within the vertices");
    for (size_t k = 0; k < 3 * (size_t)s.n_frames * (size_t)s.n_verts; k++)
        fuzz_require(isfinite(s.verts[k]), "finite vertices");
    tcb_sequence_free(&s);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *path = fuzz_file(TCB_DFAUST_FILE_M, (const uint8_t *)"", 0);
    h5prog_build(data, size, dfaust_names, DFAUST_N_NAMES, path);
    read_and_check(NULL, 0);
    char subject[] = "50002";
    char *listed[] = {subject};
    read_and_check(listed, 1);
    return 0;
}
