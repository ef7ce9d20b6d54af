// The C++ files of the meshing module (libtcbench_meshing.so) and what they
// share: each backend function behind tcb_meshing_ops (meshing/backend.h),
// the copy of a result into a malloc'ed tcb_mesh, and the guard that turns a
// library's exception into a one-line tcb_error (none may cross into C).
// C++ only; module.cpp assembles the table.
#ifndef TCB_MESHING_MODULE_H
#define TCB_MESHING_MODULE_H

#include <algorithm>
#include <cstring>
#include <exception>
#include <new>

#include "meshing/backend.h"

namespace tcb_meshing {

// open3d.cpp
int poisson(const float *pts, const float *normals, int n, int depth, tcb_mesh *out, tcb_error *err);
int decimate(const tcb_mesh *in, int max_faces, tcb_mesh *out, tcb_error *err);
int normals(const float *pts, int n, int k, float *out, tcb_error *err);
int convex_hull(const float *pts, int n, tcb_mesh *out, tcb_error *err);
// cgal.cpp
int remesh(const tcb_mesh *in, double edge_length, int iterations, tcb_mesh *out, tcb_error *err);

// A malloc'ed tcb_mesh of nv vertices and nf faces for the caller to fill
// (freed with tcb_mesh_free), or TCB_ERR_NOMEM / TCB_ERR_INTERNAL.
int alloc_mesh(size_t nv, size_t nf, tcb_mesh *out, tcb_error *err);

// Runs one library call; what it throws becomes a one-line tcb_error naming
// the library (Qhull's errors run to twenty lines: the first says what failed).
template <class F> int guarded(const char *library, const char *what, tcb_error *err, F &&call)
{
    try {
        return call();
    } catch (const std::bad_alloc &) {
        return tcb_fail(err, TCB_ERR_NOMEM, "meshing: %s: out of memory", what);
    } catch (const std::exception &e) {
        const char *msg = e.what();
        return tcb_fail(err, TCB_ERR_NUMERIC, "meshing: %s failed in %s: %.*s", what, library,
                        (int)std::min<size_t>(std::strcspn(msg, "\n"), 200), msg);
    } catch (...) {
        return tcb_fail(err, TCB_ERR_INTERNAL, "meshing: %s failed in %s (unknown exception)", what, library);
    }
}

} // namespace tcb_meshing

#endif
