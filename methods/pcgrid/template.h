/* The template of the pcgrid methods (Neu-PiG, PDG): the keyframe's
 * screened Poisson surface decimated to a triangle budget (tcb/meshing.h)
 * — for PDG remeshed isotropically first, the decimation checked against
 * the remeshed surface and the remeshing repeated until it passes (PDG
 * src/utilities/util.py) —, the vertex normals and edges that an
 * optimisation reads from it, and its OBJ for people to check
 * (scripts/keyframe_template.py). Fit and load build it the same way from
 * the same clouds, so it is rebuilt rather than stored.
 *
 * Everything here is in the grids' cube (methods/pcgrid/prepare.h) but the
 * OBJ, which is written in the sequence's coordinates. */
#ifndef TCB_PCGRID_TEMPLATE_H
#define TCB_PCGRID_TEMPLATE_H

#include <stdint.h>

#include "methods/pcgrid/prepare.h"
#include "tcb/error.h"
#include "tcb/mesh.h"
#include "tcb/sequence.h"

/* How the template is built (the method's params). */
typedef struct tcb_pcgrid_template_spec {
    int gt_normals;     /* 1: the GT face normal under each keyframe point (the reference's
                         * setting); 0: PCA normals estimated from the points */
    int poisson_depth;  /* the Poisson octree depth */
    int template_faces; /* the decimation's triangle budget */
    /* PDG's rounds (remesh_iterations 0: none, Neu-PiG's template): remesh
     * toward the mean edge length with that many iterations, decimate, and
     * accept when the Chamfer (tcb_chamfer) between check_samples samples
     * of each is below check_chamfer; else remesh the remeshed surface
     * again, at most max_rounds rounds. The samples draw from the stream
     * (seed, "pcgrid/template-check"). */
    int remesh_iterations;
    int check_samples, max_rounds;
    double check_chamfer;
    uint64_t seed;
} tcb_pcgrid_template_spec;

/* The template of frame `key` of seq from that frame's cloud [n][3],
 * already mapped into the cube by map (the GT normals bring the frame's GT
 * vertices there with it). *out, empty on entry, is left empty on failure;
 * else it is the caller's to free (tcb_mesh_free). */
int tcb_pcgrid_template_build(const tcb_sequence *seq, int key, const tcb_pcgrid_frame_map *map,
                              const float *cloud, int n, const tcb_pcgrid_template_spec *spec, tcb_mesh *out,
                              tcb_error *err);

/* The template's area-weighted vertex normals into *normals, malloc'ed
 * [t->n_verts][3] and the caller's to free; NULL on failure. */
/* Frame `frame`'s GT face normal under each of n points of its cloud
 * (in the map's frame; the cloud comes from the GT surface and the map is
 * a similarity, so face normals are the same there): normals [n][3]. An
 * error for a sequence of points alone, which has no GT surface. */
int tcb_pcgrid_gt_normals(const tcb_sequence *seq, int frame, const tcb_pcgrid_frame_map *map, const float *cloud,
                          int n, float *normals, tcb_error *err);

int tcb_pcgrid_template_normals(const tcb_mesh *t, float **normals, tcb_error *err);

/* The template's undirected edges, each once with a < b in vertex order,
 * and their lengths: *edges [*ne][2] and *edge_len [*ne], malloc'ed and the
 * caller's to free; both NULL and *ne 0 on failure. */
int tcb_pcgrid_template_edges(const tcb_mesh *t, int32_t **edges, float **edge_len, int *ne, tcb_error *err);

/* The template as fitting starts, for people to open and check against
 * the keyframe's GT mesh (scripts/keyframe_template.py): t (in the cube)
 * mapped back by map into the sequence's coordinates and written to
 * <work_dir>/template_keyframe_<keyframe>.obj; t is left as it is. */
int tcb_pcgrid_template_write(const tcb_mesh *t, const tcb_pcgrid_frame_map *map, const char *work_dir,
                              int keyframe, tcb_error *err);

#endif
