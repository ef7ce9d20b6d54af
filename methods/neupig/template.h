/* Neu-PiG's template: the keyframe's screened Poisson surface decimated to
 * a triangle budget (tcb/meshing.h), the vertex normals and edges that the
 * optimisation reads from it (methods/neupig/train.h), and its OBJ for
 * people to check (scripts/neupig_template.py). Fit and load build it the
 * same way from the same clouds, so it is rebuilt rather than stored.
 *
 * Everything here is in the grids' cube (methods/neupig/prepare.h) but the
 * OBJ, which is written in the sequence's coordinates. */
#ifndef TCB_NEUPIG_TEMPLATE_H
#define TCB_NEUPIG_TEMPLATE_H

#include <stdint.h>

#include "methods/neupig/prepare.h"
#include "tcb/error.h"
#include "tcb/mesh.h"
#include "tcb/sequence.h"

/* How the template is built (the method's params). */
typedef struct tcb_neupig_template_spec {
    int gt_normals;     /* 1: the GT face normal under each keyframe point (the reference's
                         * setting); 0: PCA normals estimated from the points */
    int poisson_depth;  /* the Poisson octree depth */
    int template_faces; /* the decimation's triangle budget */
} tcb_neupig_template_spec;

/* The template of frame `key` of seq from that frame's cloud [n][3],
 * already mapped into the cube by map (the GT normals bring the frame's GT
 * vertices there with it). *out, empty on entry, is left empty on failure;
 * else it is the caller's to free (tcb_mesh_free). */
int tcb_neupig_template_build(const tcb_sequence *seq, int key, const tcb_neupig_frame_map *map,
                              const float *cloud, int n, const tcb_neupig_template_spec *spec, tcb_mesh *out,
                              tcb_error *err);

/* The template's area-weighted vertex normals into *normals, malloc'ed
 * [t->n_verts][3] and the caller's to free; NULL on failure. */
int tcb_neupig_template_normals(const tcb_mesh *t, float **normals, tcb_error *err);

/* The template's undirected edges, each once with a < b in vertex order,
 * and their lengths: *edges [*ne][2] and *edge_len [*ne], malloc'ed and the
 * caller's to free; both NULL and *ne 0 on failure. */
int tcb_neupig_template_edges(const tcb_mesh *t, int32_t **edges, float **edge_len, int *ne, tcb_error *err);

/* The template as fitting starts, for people to open and check against
 * the keyframe's GT mesh (scripts/neupig_template.py): t (in the cube)
 * mapped back by map into the sequence's coordinates and written to
 * <work_dir>/template_keyframe_<keyframe>.obj; t is left as it is. */
int tcb_neupig_template_write(const tcb_mesh *t, const tcb_neupig_frame_map *map, const char *work_dir,
                              int keyframe, tcb_error *err);

#endif
