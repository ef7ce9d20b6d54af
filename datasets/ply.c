/* Coloured meshes and point clouds as ASCII PLY, the format mesh viewers
 * (MeshLab, Blender, Open3D, CloudCompare) open with per-vertex colours;
 * OBJ has no standard vertex colour. Written by hand because it is a
 * header and two loops: no Debian library for PLY is worth a dependency. */
#include <stdio.h>

#include "tcb/fsutil.h"
#include "tcb/mesh_io.h"

int tcb_ply_write(const char *path, const float *verts, int nv, const int32_t *faces, int nf,
                  const uint8_t *rgb, tcb_error *err)
{
    if (nv <= 0 || nf < 0 || (nf > 0 && !faces))
        return tcb_fail(err, TCB_ERR_INPUT, "%s: %d vertices and %d faces is no mesh", path, nv,
                        nf);
    tcb_atomic_file af;
    int rc = tcb_atomic_open(&af, path, err);
    if (rc) return rc;
    fprintf(af.fp, "ply\nformat ascii 1.0\ncomment written by tcbench\n"
                   "element vertex %d\nproperty float x\nproperty float y\nproperty float z\n",
            nv);
    if (rgb)
        fprintf(af.fp, "property uchar red\nproperty uchar green\nproperty uchar blue\n");
    if (nf > 0) fprintf(af.fp, "element face %d\nproperty list uchar int vertex_indices\n", nf);
    fprintf(af.fp, "end_header\n");
    /* %.9g round-trips every float exactly. */
    for (int i = 0; i < nv; i++) {
        const float *v = verts + 3 * (size_t)i;
        fprintf(af.fp, "%.9g %.9g %.9g", v[0], v[1], v[2]);
        if (rgb) {
            const uint8_t *c = rgb + 3 * (size_t)i;
            fprintf(af.fp, " %d %d %d", c[0], c[1], c[2]);
        }
        fputc('\n', af.fp);
    }
    for (int i = 0; i < nf; i++) {
        const int32_t *f = faces + 3 * (size_t)i;
        fprintf(af.fp, "3 %d %d %d\n", f[0], f[1], f[2]);
    }
    return tcb_atomic_commit(&af, err);
}
