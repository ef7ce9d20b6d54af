/* tcbench — the Wavefront OBJ reader/writer and a PLY writer for coloured
 * meshes (datasets/obj.c, datasets/ply.c).
 *
 * The reader accepts `v x y z`, `f` with `v`, `v/vt`, `v//vn`, `v/vt/vn`
 * forms, negative (relative) indices, polygons (fan-triangulated) and
 * comments; it ignores vt/vn/o/g/s/usemtl/mtllib lines. It rejects bad
 * numbers, NaN/Inf, zero or out-of-range indices, faces with < 3 vertices
 * and files without faces, naming file and line. */
#ifndef TCB_MESH_IO_H
#define TCB_MESH_IO_H

#include <stdint.h>

#include "tcb/error.h"
#include "tcb/mesh.h"

#ifdef __cplusplus
extern "C" {
#endif

int tcb_obj_read(const char *path, tcb_mesh *out, tcb_error *err);
/* Written atomically. */
int tcb_obj_write(const char *path, const float *verts, int nv, const int32_t *faces,
                  int nf, tcb_error *err);
/* A mesh (nf > 0) or point cloud (nf = 0, faces NULL) as ASCII PLY with
 * optional per-vertex colours rgb [nv][3] (NULL: none); written atomically.
 * (datasets/ply.c) */
int tcb_ply_write(const char *path, const float *verts, int nv, const int32_t *faces, int nf,
                  const uint8_t *rgb, tcb_error *err);

#ifdef __cplusplus
}
#endif
#endif
