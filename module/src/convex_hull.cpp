// Convex hull via CGAL::convex_hull_3 (exact predicates, inexact constructions).
#include "convex_hull.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/convex_hull_3.h>

#include <algorithm>
#include <array>
#include <tuple>
#include <map>

namespace aggrelod::detail {
namespace {
using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Mesh = CGAL::Surface_mesh<Point>;

bool spansThreeDimensions(const std::vector<Point>& pts) {
    if (pts.size() < 4) return false;
    // Find a non-degenerate tetrahedron with exact predicates.
    size_t i1 = 1;
    while (i1 < pts.size() && pts[i1] == pts[0]) ++i1;
    if (i1 == pts.size()) return false;
    size_t i2 = i1 + 1;
    while (i2 < pts.size() && CGAL::collinear(pts[0], pts[i1], pts[i2])) ++i2;
    if (i2 >= pts.size()) return false;
    for (size_t i3 = i2 + 1; i3 < pts.size(); ++i3)
        if (!CGAL::coplanar(pts[0], pts[i1], pts[i2], pts[i3])) return true;
    return false;
}

bool hullMesh(const std::vector<double>& points, Mesh& mesh) {
    std::vector<Point> pts;
    pts.reserve(points.size() / 3);
    for (size_t i = 0; i + 2 < points.size(); i += 3) pts.emplace_back(points[i], points[i + 1], points[i + 2]);
    if (!spansThreeDimensions(pts)) return false;
    CGAL::convex_hull_3(pts.begin(), pts.end(), mesh);
    return mesh.number_of_faces() >= 4;
}
}  // namespace

bool convexHull3(const std::vector<double>& points, std::vector<double>& hullPositions,
                 std::vector<uint32_t>& hullTriangles) {
    hullPositions.clear();
    hullTriangles.clear();
    Mesh mesh;
    if (!hullMesh(points, mesh)) return false;
    // Deterministic vertex order: sort hull vertices by coordinates.
    std::vector<std::pair<Point, Mesh::Vertex_index>> verts;
    for (auto v : mesh.vertices()) verts.emplace_back(mesh.point(v), v);
    std::sort(verts.begin(), verts.end(), [](const auto& a, const auto& b) {
        return std::make_tuple(a.first.x(), a.first.y(), a.first.z()) < std::make_tuple(b.first.x(), b.first.y(), b.first.z());
    });
    std::map<Mesh::Vertex_index, uint32_t> remap;
    for (size_t i = 0; i < verts.size(); ++i) {
        remap[verts[i].second] = static_cast<uint32_t>(i);
        hullPositions.push_back(verts[i].first.x());
        hullPositions.push_back(verts[i].first.y());
        hullPositions.push_back(verts[i].first.z());
    }
    std::vector<std::array<uint32_t, 3>> tris;
    for (auto f : mesh.faces()) {
        std::array<uint32_t, 3> t{};
        int k = 0;
        for (auto v : CGAL::vertices_around_face(mesh.halfedge(f), mesh)) {
            if (k < 3) t[k] = remap[v];
            ++k;
        }
        if (k != 3) continue;
        // rotate so the smallest index comes first (keeps orientation)
        while (t[0] > t[1] || t[0] > t[2]) t = {t[1], t[2], t[0]};
        tris.push_back(t);
    }
    std::sort(tris.begin(), tris.end());
    for (auto& t : tris) hullTriangles.insert(hullTriangles.end(), t.begin(), t.end());
    return true;
}

double convexHullVolume(const std::vector<double>& points) {
    Mesh mesh;
    if (!hullMesh(points, mesh)) return 0.0;
    double volume = 0;
    const Point origin = mesh.point(*mesh.vertices().begin());
    for (auto f : mesh.faces()) {
        std::array<Point, 3> p;
        int k = 0;
        for (auto v : CGAL::vertices_around_face(mesh.halfedge(f), mesh)) {
            if (k < 3) p[k] = mesh.point(v);
            ++k;
        }
        volume += CGAL::volume(origin, p[0], p[1], p[2]);
    }
    return volume;
}

}  // namespace aggrelod::detail
