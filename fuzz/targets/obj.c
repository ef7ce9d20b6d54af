/* The Wavefront OBJ frame reader (datasets/obj.c): any bytes as a frame
 * file; a mesh read has finite vertices and triangles indexing them. */
#include <math.h>

#include "fuzz/fuzz_util.h"
#include "tcb/mesh_io.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *path = fuzz_file("frame.obj", data, size);
    tcb_mesh m;
    tcb_error err = {0};
    int rc = tcb_obj_read(path, &m, &err);
    fuzz_check_answer(rc, &err, path);
    if (rc) return 0;
    fuzz_require(m.n_verts > 0 && m.n_faces > 0, "a mesh read has vertices and faces");
    for (int k = 0; k < 3 * m.n_verts; k++) fuzz_require(isfinite(m.verts[k]), "finite coordinates");
    for (int k = 0; k < 3 * m.n_faces; k++)
        fuzz_require(m.faces[k] >= 0 && m.faces[k] < m.n_verts, "face indices within the vertices");
    tcb_mesh_free(&m);
    return 0;
}
