// The CGAL half of the meshing module: isotropic remeshing (Botsch & Kobbelt
// 2004) from CGAL 5.5's Polygon Mesh Processing (Debian's libcgal-dev),
// which PDG's template asks for where its reference calls gpytoolbox's
// remesh_botsch. Inputs arrive checked by meshing/meshing.c.
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/remesh.h>
#include <CGAL/Polygon_mesh_processing/repair_polygon_soup.h>
#include <CGAL/Surface_mesh.h>

#include <array>
#include <vector>

#include "meshing/module.h"

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Mesh = CGAL::Surface_mesh<Point>;
namespace PMP = CGAL::Polygon_mesh_processing;

// The triangles as a polygon soup made a valid halfedge mesh: duplicate
// points and degenerate or repeated faces removed, faces oriented
// consistently, non-manifold vertices split (a Poisson surface can pinch).
Mesh to_surface_mesh(const tcb_mesh *in)
{
    std::vector<Point> points(in->n_verts);
    for (int i = 0; i < in->n_verts; i++) {
        const float *p = in->verts + 3 * i;
        points[i] = Point(p[0], p[1], p[2]);
    }
    std::vector<std::array<std::size_t, 3>> faces(in->n_faces);
    for (int i = 0; i < in->n_faces; i++)
        for (int d = 0; d < 3; d++) faces[i][d] = (std::size_t)in->faces[3 * i + d];
    PMP::repair_polygon_soup(points, faces);
    PMP::orient_polygon_soup(points, faces);
    Mesh m;
    PMP::polygon_soup_to_polygon_mesh(points, faces, m);
    return m;
}

int to_tcb_mesh(const Mesh &m, tcb_mesh *out, tcb_error *err)
{
    int rc = tcb_meshing::alloc_mesh(m.number_of_vertices(), m.number_of_faces(), out, err);
    if (rc) return rc;
    int k = 0;
    for (Mesh::Vertex_index v : m.vertices()) {
        const Point &p = m.point(v);
        for (int d = 0; d < 3; d++) out->verts[3 * k + d] = (float)CGAL::to_double(p[d]);
        k++;
    }
    k = 0;
    for (Mesh::Face_index f : m.faces()) {
        int d = 0;
        for (Mesh::Vertex_index v : CGAL::vertices_around_face(m.halfedge(f), m)) out->faces[3 * k + d++] = (int32_t)v;
        k++;
    }
    return TCB_OK;
}

} // namespace

namespace tcb_meshing {

// CGAL's defaults but for the length and the iterations: every face
// remeshed, border edges kept on the border (split and collapsed, not
// moved off it), vertices projected back onto the input surface after each
// smoothing step, as remesh_botsch does.
int remesh(const tcb_mesh *in, double edge_length, int iterations, tcb_mesh *out, tcb_error *err)
{
    return guarded("CGAL", "isotropic remeshing", err, [&] {
        Mesh m = to_surface_mesh(in);
        if (m.number_of_faces() == 0)
            return tcb_fail(err, TCB_ERR_INPUT, "meshing: isotropic remeshing: no valid triangle in the mesh");
        PMP::isotropic_remeshing(m.faces(), edge_length, m, CGAL::parameters::number_of_iterations(iterations));
        m.collect_garbage();
        return to_tcb_mesh(m, out, err);
    });
}

} // namespace tcb_meshing
