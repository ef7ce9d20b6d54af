/* tcbench — one triangle mesh: the type every room passes meshes in, and
 * its destructor, here with the type so that a room that only passes
 * meshes (meshing/) needs no file reader. Reading and writing files:
 * tcb/mesh_io.h. */
#ifndef TCB_MESH_H
#define TCB_MESH_H

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct tcb_mesh {
    int n_verts;
    int n_faces;
    float *verts;    /* [n_verts][3] */
    int32_t *faces;  /* [n_faces][3], 0-based */
} tcb_mesh;

static inline void tcb_mesh_free(tcb_mesh *m)
{
    free(m->verts);
    free(m->faces);
    memset(m, 0, sizeof *m);
}

#ifdef __cplusplus
}
#endif
#endif
