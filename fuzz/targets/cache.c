/* The HDF5 sequence cache (datasets/cache.c), structure-aware (see
 * fuzz/h5_program.h): a cache loaded has faces within its vertices and
 * finite coordinates, areas and pools. Its last check is the checksum of
 * the arrays (format 5), which a program matches only by chance: the
 * search covers every check before it, and the checksum's own tests are
 * unit tests (tests/unit/test_cache.c). */
#include <math.h>

#include "fuzz/fuzz_util.h"
#include "fuzz/h5_names.h"
#include "fuzz/h5_program.h"
#include "tcb/geometry.h"
#include "tcb/sequence.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *path = fuzz_file("cache.h5", (const uint8_t *)"", 0);
    h5prog_build(data, size, cache_names, CACHE_N_NAMES, path);
    tcb_sequence s;
    tcb_error err = {0};
    int rc = tcb_sequence_cache_load(path, CACHE_KEY_TEXT, &s, &err);
    fuzz_check_answer(rc, &err, path);
    if (rc) return 0;
    size_t F = (size_t)s.n_frames, V = (size_t)s.n_verts;
    for (size_t k = 0; k < 3 * (size_t)s.n_faces; k++)
        fuzz_require(s.faces[k] >= 0 && s.faces[k] < s.n_verts, "faces within the vertices");
    fuzz_require(tcb_all_finite(s.verts, F * V * 3), "finite vertices");
    fuzz_require(tcb_all_finite_d(s.areas, F) && tcb_all_finite_d(s.norm_shift, 3 * F) && isfinite(s.norm_scale),
                 "finite areas and normalization");
    fuzz_require(!s.pools || tcb_all_finite(s.pools, F * (size_t)s.pool_size * 3), "finite pools");
    fuzz_require(!s.yaw || tcb_all_finite_d(s.yaw, F), "finite yaw");
    tcb_sequence_free(&s);
    return 0;
}
