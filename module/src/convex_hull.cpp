// SPDX-License-Identifier: AGPL-3.0-or-later
// Convex hull via CGAL::convex_hull_3 (exact predicates, inexact constructions).
#include "convex_hull.h"

#include <aggrelod/disjoint_sets.h>

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

// CGAL triangulates a hull facet with more than three coplanar vertices (a ring of a UV
// sphere, a box side) in an order that varies from run to run. Merge coplanar neighbours
// into polygons and fan each one from its smallest vertex, so the output is canonical.
void canonicalTriangulation(const std::vector<double>& positions, std::vector<std::array<uint32_t, 3>>& tris) {
    auto point = [&](uint32_t v) { return Point(positions[3 * v], positions[3 * v + 1], positions[3 * v + 2]); };
    // Directed edge -> face, as a sorted array (hulls are small; this runs once per group).
    struct EdgeFace {
        uint32_t u, v;
        size_t face;
        bool operator<(const EdgeFace& o) const { return std::tie(u, v) < std::tie(o.u, o.v); }
    };
    std::vector<EdgeFace> faceOfEdge;
    faceOfEdge.reserve(3 * tris.size());
    for (size_t f = 0; f < tris.size(); ++f)
        for (int k = 0; k < 3; ++k) faceOfEdge.push_back({tris[f][k], tris[f][(k + 1) % 3], f});
    std::sort(faceOfEdge.begin(), faceOfEdge.end());
    auto faceAcross = [&](uint32_t u, uint32_t v) -> long {
        auto it = std::lower_bound(faceOfEdge.begin(), faceOfEdge.end(), EdgeFace{u, v, 0});
        return it != faceOfEdge.end() && it->u == u && it->v == v ? static_cast<long>(it->face) : -1;
    };
    DisjointSets facets(tris.size());
    auto find = [&](size_t x) -> size_t { return facets.find(uint32_t(x)); };
    for (size_t f = 0; f < tris.size(); ++f)
        for (int k = 0; k < 3; ++k) {
            const long other = faceAcross(tris[f][(k + 1) % 3], tris[f][k]);
            if (other < 0) continue;
            const auto& g = tris[static_cast<size_t>(other)];
            uint32_t apex = g[0] + g[1] + g[2] - tris[f][k] - tris[f][(k + 1) % 3];
            if (CGAL::coplanar(point(tris[f][0]), point(tris[f][1]), point(tris[f][2]), point(apex)))
                facets.unite(uint32_t(f), uint32_t(other));
        }
    // Boundary edges of each merged facet (root, u -> v), sorted by (root, u).
    std::vector<std::array<uint64_t, 3>> boundary;
    for (size_t f = 0; f < tris.size(); ++f) {
        const size_t root = find(f);
        for (int k = 0; k < 3; ++k) {
            uint32_t u = tris[f][k], v = tris[f][(k + 1) % 3];
            const long other = faceAcross(v, u);
            if (other >= 0 && find(static_cast<size_t>(other)) == root) continue;  // inner edge
            boundary.push_back({root, u, v});
        }
    }
    std::sort(boundary.begin(), boundary.end());
    std::vector<std::array<uint32_t, 3>> out;
    std::vector<uint32_t> loop;
    for (size_t i = 0; i < boundary.size();) {
        size_t j = i;
        while (j < boundary.size() && boundary[j][0] == boundary[i][0]) ++j;
        auto next = [&](uint64_t u) -> uint64_t {
            auto it = std::lower_bound(boundary.begin() + i, boundary.begin() + j, std::array<uint64_t, 3>{boundary[i][0], u, 0});
            return it != boundary.begin() + j && (*it)[1] == u ? (*it)[2] : u;
        };
        const uint64_t start = boundary[i][1];  // smallest vertex of the polygon
        loop.assign(1, static_cast<uint32_t>(start));
        for (uint64_t v = next(start); v != start && loop.size() <= j - i; v = next(v)) loop.push_back(static_cast<uint32_t>(v));
        for (size_t k = 1; k + 1 < loop.size(); ++k) out.push_back({loop[0], loop[k], loop[k + 1]});
        i = j;
    }
    std::sort(out.begin(), out.end());
    tris = std::move(out);
}
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
    std::vector<uint32_t> remap(mesh.number_of_vertices() + mesh.number_of_removed_vertices(), 0);  // by vertex index
    for (size_t i = 0; i < verts.size(); ++i) {
        remap[static_cast<size_t>(verts[i].second)] = static_cast<uint32_t>(i);
        hullPositions.push_back(verts[i].first.x());
        hullPositions.push_back(verts[i].first.y());
        hullPositions.push_back(verts[i].first.z());
    }
    std::vector<std::array<uint32_t, 3>> tris;
    for (auto f : mesh.faces()) {
        std::array<uint32_t, 3> t{};
        int k = 0;
        for (auto v : CGAL::vertices_around_face(mesh.halfedge(f), mesh)) {
            if (k < 3) t[k] = remap[static_cast<size_t>(v)];
            ++k;
        }
        if (k != 3) continue;
        // rotate so the smallest index comes first (keeps orientation)
        while (t[0] > t[1] || t[0] > t[2]) t = {t[1], t[2], t[0]};
        tris.push_back(t);
    }
    canonicalTriangulation(hullPositions, tris);
    for (auto& t : tris) hullTriangles.insert(hullTriangles.end(), t.begin(), t.end());
    return true;
}

double convexHullVolume(const std::vector<double>& points, std::vector<double>* hullVertices) {
    std::vector<double> positions;
    std::vector<uint32_t> triangles;
    if (!convexHull3(points, positions, triangles)) {
        if (hullVertices) *hullVertices = points;
        return 0.0;
    }
    // Canonical triangles in sorted order, relative to the first (smallest) vertex.
    double volume = 0;
    const double* o = &positions[0];
    for (size_t t = 0; t + 2 < triangles.size(); t += 3) {
        double r[3][3];
        for (int k = 0; k < 3; ++k)
            for (int d = 0; d < 3; ++d) r[k][d] = positions[3 * triangles[t + k] + d] - o[d];
        volume += (r[0][0] * (r[1][1] * r[2][2] - r[1][2] * r[2][1]) - r[0][1] * (r[1][0] * r[2][2] - r[1][2] * r[2][0]) +
                   r[0][2] * (r[1][0] * r[2][1] - r[1][1] * r[2][0])) / 6.0;
    }
    if (hullVertices) *hullVertices = std::move(positions);
    return volume;
}

}  // namespace aggrelod::detail
