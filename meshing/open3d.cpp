// The Open3D half of the meshing module: tcbench's C calls turned into
// Open3D 0.16 calls (screened Poisson, quadric decimation, PCA normals,
// the convex hull).
// Inputs arrive checked by meshing/meshing.c.
#include <open3d/geometry/KDTreeSearchParam.h>
#include <open3d/geometry/PointCloud.h>
#include <open3d/geometry/TriangleMesh.h>
#include <open3d/utility/Logging.h>

#include <cstdlib>
#include <limits>
#include <memory>

#include "meshing/module.h"

namespace {

using open3d::geometry::PointCloud;
using open3d::geometry::TriangleMesh;

PointCloud make_cloud(const float *pts, const float *normals, int n)
{
    PointCloud pc;
    pc.points_.resize(n);
    if (normals) pc.normals_.resize(n);
    for (int i = 0; i < n; i++) {
        const float *p = pts + 3 * i;
        pc.points_[i] = Eigen::Vector3d(p[0], p[1], p[2]);
        if (normals) pc.normals_[i] = Eigen::Vector3d(normals[3 * i], normals[3 * i + 1], normals[3 * i + 2]);
    }
    return pc;
}

// Copies Open3D's mesh into a malloc'ed tcb_mesh.
int to_tcb_mesh(const TriangleMesh &m, tcb_mesh *out, tcb_error *err)
{
    const size_t nv = m.vertices_.size(), nf = m.triangles_.size();
    int rc = tcb_meshing::alloc_mesh(nv, nf, out, err);
    if (rc) return rc;
    for (size_t i = 0; i < nv; i++)
        for (int d = 0; d < 3; d++) out->verts[3 * i + d] = (float)m.vertices_[i][d];
    for (size_t i = 0; i < nf; i++)
        for (int d = 0; d < 3; d++) out->faces[3 * i + d] = m.triangles_[i][d];
    return TCB_OK;
}

// Open3D reports through exceptions and prints warnings; a library of
// tcbench never prints, so only errors (thrown, then caught) remain.
template <class F> int open3d_call(const char *what, tcb_error *err, F &&call)
{
    return tcb_meshing::guarded("Open3D", what, err, [&] {
        open3d::utility::SetVerbosityLevel(open3d::utility::VerbosityLevel::Error);
        return call();
    });
}

} // namespace

namespace tcb_meshing {

// Open3D's defaults but for depth and threads: width 0 (depth decides),
// scale 1.1 (the cube around the points; MeshLab's default too), no linear
// fit (MeshLab's default too), one thread (the reference's threads=1; the
// vertex order depends on the thread count).
int poisson(const float *pts, const float *normals, int n, int depth, tcb_mesh *out, tcb_error *err)
{
    return open3d_call("screened Poisson", err, [&] {
        PointCloud pc = make_cloud(pts, normals, n);
        auto result = TriangleMesh::CreateFromPointCloudPoisson(pc, (size_t)depth, 0.0f, 1.1f, false, 1);
        return to_tcb_mesh(*std::get<0>(result), out, err);
    });
}

// Open3D's quadric decimation with the defaults the reference uses
// (simplify_quadric_decimation(target)): no error bound, boundary weight 1.
int decimate(const tcb_mesh *in, int max_faces, tcb_mesh *out, tcb_error *err)
{
    return open3d_call("quadric decimation", err, [&] {
        TriangleMesh m;
        m.vertices_.resize(in->n_verts);
        m.triangles_.resize(in->n_faces);
        for (int i = 0; i < in->n_verts; i++) {
            const float *p = in->verts + 3 * i;
            m.vertices_[i] = Eigen::Vector3d(p[0], p[1], p[2]);
        }
        for (int i = 0; i < in->n_faces; i++) {
            const int32_t *t = in->faces + 3 * i;
            m.triangles_[i] = Eigen::Vector3i(t[0], t[1], t[2]);
        }
        auto simple = m.SimplifyQuadricDecimation(max_faces, std::numeric_limits<double>::infinity(), 1.0);
        simple->RemoveUnreferencedVertices();
        return to_tcb_mesh(*simple, out, err);
    });
}

// PCA normals (Eigen's symmetric eigen-solver, not Open3D's closed-form
// "fast" one, which loses accuracy on nearly planar neighbourhoods), then
// Hoppe's propagation along the minimum spanning tree of the Delaunay and
// k-NN graph.
int normals(const float *pts, int n, int k, float *out, tcb_error *err)
{
    return open3d_call("normal estimation", err, [&] {
        PointCloud pc = make_cloud(pts, nullptr, n);
        pc.EstimateNormals(open3d::geometry::KDTreeSearchParamKNN(k), false);
        pc.OrientNormalsConsistentTangentPlane((size_t)k);
        for (int i = 0; i < n; i++) {
            Eigen::Vector3d u = pc.normals_[i].normalized();
            for (int d = 0; d < 3; d++) out[3 * i + d] = (float)u[d];
        }
        return (int)TCB_OK;
    });
}

// The convex hull as DynoSurf's grid takes it (open3d's
// compute_convex_hull: Qhull's triangulated hull, no joggling). The
// triangles' winding is meshing.c's to fix.
int convex_hull(const float *pts, int n, tcb_mesh *out, tcb_error *err)
{
    return open3d_call("convex hull", err, [&] {
        PointCloud pc = make_cloud(pts, nullptr, n);
        auto hull = std::get<0>(pc.ComputeConvexHull(false));
        return to_tcb_mesh(*hull, out, err);
    });
}

} // namespace tcb_meshing
