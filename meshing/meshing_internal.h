/* What meshing/'s C files share and keep to the room. */
#ifndef TCB_MESHING_INTERNAL_H
#define TCB_MESHING_INTERNAL_H

#include "tcb/error.h"
#include "tcb/mesh.h"

/* A mesh's input check: at least 3 vertices and a face, finite
 * coordinates, face indices in range (meshing.c). */
int tcb_meshing_check_mesh(const tcb_mesh *m, tcb_error *err);

#endif
