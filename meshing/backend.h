/* The function table between meshing/meshing.c (in libtcbench) and the C++
 * module libtcbench_meshing.so (meshing/module.cpp: Open3D's functions in
 * open3d.cpp, CGAL's in cgal.cpp). meshing.c has checked every input before
 * a call (counts, finite coordinates, index ranges, non-zero normals), so
 * the module only converts, calls the library and turns its exceptions into
 * a tcb_error. */
#ifndef TCB_MESHING_BACKEND_H
#define TCB_MESHING_BACKEND_H

#include "tcb/error.h"
#include "tcb/mesh.h"

#ifdef __cplusplus
extern "C" {
#endif

#define TCB_MESHING_MODULE "libtcbench_meshing.so"
#define TCB_MESHING_ENTRY "tcb_meshing_backend"

typedef struct tcb_meshing_ops {
    int (*poisson)(const float *pts, const float *normals, int n, int depth, tcb_mesh *out,
                   tcb_error *err);
    int (*decimate)(const tcb_mesh *in, int max_faces, tcb_mesh *out, tcb_error *err);
    /* PCA normals oriented consistently; the sign of the whole set is
     * meshing.c's to choose. */
    int (*normals)(const float *pts, int n, int k, float *normals, tcb_error *err);
    /* CGAL's isotropic remeshing toward edge_length, `iterations` rounds. */
    int (*remesh)(const tcb_mesh *in, double edge_length, int iterations, tcb_mesh *out, tcb_error *err);
    /* Qhull's convex hull (through Open3D), triangles in any winding. */
    int (*convex_hull)(const float *pts, int n, tcb_mesh *out, tcb_error *err);
} tcb_meshing_ops;

typedef const tcb_meshing_ops *(*tcb_meshing_entry_fn)(void);

#ifdef __cplusplus
}
#endif
#endif
