/* tcbench — meshing a point cloud: screened Poisson surface reconstruction
 * (Kazhdan & Hoppe 2013) of oriented points, quadric edge-collapse
 * decimation (Garland & Heckbert 1997), and PCA normals with a consistent
 * orientation (Hoppe et al. 1992). Neu-PiG's template is the keyframe's
 * Poisson surface decimated to ≤ 20 000 triangles (docs/meshing.md).
 *
 * The work is done by Open3D 0.16 (Debian's libopen3d-dev), the one Debian
 * geometry library that implements the *screened* Poisson solver (CGAL
 * 5.5's Poisson_surface_reconstruction_3 and PCL 1.13's pcl::Poisson are the
 * unscreened 2006 method) and the reference's own decimation (neu-pig calls
 * Open3D's simplify_quadric_decimation). Open3D is reached through a thin
 * C++ module, libtcbench_meshing.so beside libtcbench, which these functions
 * load on first use: linking it into libtcbench would load Open3D's 100
 * shared libraries into every tcbench process (docs/meshing.md, "Why a
 * module"). Without the module every function fails with
 * TCB_ERR_UNSUPPORTED.
 *
 * Inputs are float xyz rows; coordinates that are not finite are
 * TCB_ERR_NUMERIC, malformed input (counts, indices, zero normals,
 * parameters out of range) TCB_ERR_INPUT. Output meshes are malloc'ed into
 * a tcb_mesh (free with tcb_mesh_free); on failure *out is left empty. */
#ifndef TCB_MESHING_H
#define TCB_MESHING_H

#include "tcb/error.h"
#include "tcb/mesh.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The reference's settings (neu-pig src/io/initialization.py and
 * src/utilities/util.py). */
#define TCB_POISSON_DEPTH 10      /* octree depth */
#define TCB_DECIMATE_FACES 20000  /* triangle budget of the template */
#define TCB_NORMALS_K 16          /* neighbours of a PCA normal (the reference's pcl mode) */

#define TCB_POISSON_DEPTH_MIN 2   /* Open3D refuses less */
#define TCB_POISSON_DEPTH_MAX 12  /* 8·4^12 nodes at worst: beyond any keyframe's need */

/* Screened Poisson surface of n ≥ 4 points with normals (any length > 0:
 * they are normalised), at octree depth `depth` (the reference: 10), on a
 * cube 1.1 times the points' bounding cube. One thread, so the mesh is the
 * same on every machine. Open3D fixes the screening weight at 2 where the
 * reference asks for 10 (docs/meshing.md lists every such difference). The
 * surface is not trimmed by density: it is closed, faces wound outward. */
int tcb_poisson_reconstruct(const float *pts, const float *normals, int n, int depth,
                            tcb_mesh *out, tcb_error *err);

/* The mesh reduced by quadric edge collapse to at most max_faces ≥ 4
 * triangles (a copy when it has no more already); unreferenced vertices
 * are dropped. */
int tcb_mesh_decimate(const tcb_mesh *in, int max_faces, tcb_mesh *out, tcb_error *err);

/* The mesh remeshed toward edges of length edge_length (> 0) by
 * Botsch & Kobbelt's isotropic remeshing (CGAL's Polygon Mesh Processing:
 * split edges longer than 4/3·h, collapse those shorter than 4/5·h, flip
 * toward valence 6, tangential smoothing, projection back onto the input),
 * `iterations` rounds (1 to TCB_REMESH_ITERATIONS_MAX). The input is taken
 * as a triangle soup and repaired first (duplicate points merged,
 * degenerate faces dropped, orientation made consistent, non-manifold
 * vertices split); border edges stay on the border. A length that would
 * make more than TCB_REMESH_FACES_MAX triangles is refused. */
#define TCB_REMESH_ITERATIONS_MAX 100
#define TCB_REMESH_FACES_MAX 2000000
int tcb_mesh_remesh(const tcb_mesh *in, double edge_length, int iterations, tcb_mesh *out, tcb_error *err);

/* Unit normals [n][3] of n ≥ 4 points: the least-variance axis of each
 * point's k nearest neighbours (3 ≤ k, capped at n), oriented consistently
 * by propagation along a minimum spanning tree of the k-NN graph, and
 * finally turned outward as a whole: Σ n_i·(p_i − c) > 0, which for points
 * spread evenly over a closed surface is the divergence theorem's 3·volume
 * (true for any closed shape, convex or not). */
int tcb_estimate_normals(const float *pts, int n, int k, float *normals, tcb_error *err);

/* The convex hull of n ≥ 4 points that do not all lie in a plane (Qhull,
 * through Open3D's compute_convex_hull, as DynoSurf's grid takes it):
 * closed, triangulated, every face wound outward. Points on the hull's
 * faces but not at its corners are not vertices of it. */
int tcb_convex_hull(const float *pts, int n, tcb_mesh *out, tcb_error *err);

/* The boundary of the points' convex hull grown by `offset` (> 0): the
 * Minkowski sum of the hull with a ball, the ball taken as the polytope of
 * TCB_OFFSET_DIRECTIONS directions (a Fibonacci lattice, ~0.25 rad
 * apart), so the surface lies within 2 % of offset inside the exact
 * rounded one (its vertices between 0.985 and 1 offset from the hull in
 * tests/unit/test_tetmesh.c). It is the convex hull of every hull vertex
 * moved by offset along every direction, which for a convex set is exact
 * up to that ball. DynoSurf's grid shell is this
 * surface remeshed (MeshLab resamples the hull's distance field instead;
 * docs/meshing.md). */
#define TCB_OFFSET_DIRECTIONS 200
int tcb_convex_offset(const float *pts, int n, double offset, tcb_mesh *out, tcb_error *err);

/* The signed distance of n queries [n][3] to a closed convex surface wound
 * outward (tcb_convex_hull's output): the distance to the closest surface
 * point (tcb_mesh_locate), negative inside — inside meaning on the inner
 * side of every face's plane, which for a convex surface is the solid.
 * DynoSurf pretrains its shape network to this field of the keyframe's
 * hull. sd [n]. */
int tcb_convex_signed_distance(const tcb_mesh *hull, const float *queries, int n, float *sd, tcb_error *err);

#ifdef __cplusplus
}
#endif
#endif
