/* tcbench — tetrahedral meshes: the type, and a closed surface filled with
 * tetrahedra by TetGen (Si 2015), Debian's `tetgen` program run as a
 * subprocess on files it reads and writes (meshing/tetgen.c). DynoSurf's
 * grid is the offset hull of its keyframe filled this way (its reference
 * calls TetGen through pyvista's wrapper with the same switches). */
#ifndef TCB_TETMESH_H
#define TCB_TETMESH_H

#include <stdint.h>

#include "tcb/error.h"
#include "tcb/mesh.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct tcb_tetmesh {
    int n_verts;
    int n_tets;
    float *verts;    /* [n_verts][3] */
    int32_t *tets;   /* [n_tets][4], 0-based, each positively oriented:
                        (v1 − v0) · ((v2 − v0) × (v3 − v0)) > 0 */
} tcb_tetmesh;

void tcb_tetmesh_free(tcb_tetmesh *t);

/* The program run; found on PATH. */
#define TCB_TETGEN_PROGRAM "tetgen"

/* The inside of `shell` (closed, not self-intersecting, any consistent
 * winding) filled with tetrahedra of volume at most max_volume (> 0: TetGen's
 * refinement target, which a few tets by the shell exceed, 0.02 % of
 * DynoSurf's crane grid by up to 1.5 times) and radius-edge ratio at most
 * radius_edge (≥ 1.1, TetGen's smallest useful bound; DynoSurf's 2.0):
 * `tetgen -pq<radius_edge>a<max_volume>`, Steiner
 * points as TetGen needs them. The shell's vertices are the first
 * shell->n_verts vertices of the result, in order. The work happens in a
 * fresh directory under $TMPDIR (else /tmp), removed afterwards.
 *
 * Errors: TCB_ERR_UNSUPPORTED when the program is not on PATH (scripts/
 * setup.sh installs Debian's tetgen); TCB_ERR_NUMERIC when it fails (a
 * self-intersecting or open shell), with the last line it printed;
 * TCB_ERR_INPUT for
 * an empty shell or out-of-range parameters; TCB_ERR_IO naming the file
 * and line of an output TetGen left malformed. *out is empty on failure. */
int tcb_tetrahedralize(const tcb_mesh *shell, double max_volume, double radius_edge, tcb_tetmesh *out,
                       tcb_error *err);

#ifdef __cplusplus
}
#endif
#endif
