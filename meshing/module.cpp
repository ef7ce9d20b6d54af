// The meshing module's table (meshing/backend.h) and what its halves share.
// Built as libtcbench_meshing.so, which meshing/meshing.c loads when a
// meshing function is first called.
#include <cstdlib>
#include <limits>

#include "meshing/module.h"

namespace tcb_meshing {

int alloc_mesh(size_t nv, size_t nf, tcb_mesh *out, tcb_error *err)
{
    const size_t most = (size_t)std::numeric_limits<int>::max() / 3;
    if (nv > most || nf > most)
        return tcb_fail(err, TCB_ERR_INTERNAL, "meshing: the mesh has too many elements (%zu vertices, %zu faces)", nv,
                        nf);
    float *v = static_cast<float *>(std::malloc(3 * (nv ? nv : 1) * sizeof(float)));
    int32_t *f = static_cast<int32_t *>(std::malloc(3 * (nf ? nf : 1) * sizeof(int32_t)));
    if (!v || !f) {
        std::free(v);
        std::free(f);
        return tcb_fail(err, TCB_ERR_NOMEM, "meshing: out of memory for a mesh of %zu vertices", nv);
    }
    out->verts = v;
    out->faces = f;
    out->n_verts = (int)nv;
    out->n_faces = (int)nf;
    return TCB_OK;
}

namespace {
const tcb_meshing_ops ops = {poisson, decimate, normals, remesh, convex_hull};
}

} // namespace tcb_meshing

extern "C" __attribute__((visibility("default"))) const tcb_meshing_ops *tcb_meshing_backend(void)
{
    return &tcb_meshing::ops;
}
