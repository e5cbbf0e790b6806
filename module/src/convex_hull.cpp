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

// CGAL triangulates a hull facet with more than three coplanar vertices (a ring of a UV
// sphere, a box side) in an order that varies from run to run. Merge coplanar neighbours
// into polygons and fan each one from its smallest vertex, so the output is canonical.
void canonicalTriangulation(const std::vector<double>& positions, std::vector<std::array<uint32_t, 3>>& tris) {
    auto point = [&](uint32_t v) { return Point(positions[3 * v], positions[3 * v + 1], positions[3 * v + 2]); };
    std::map<std::pair<uint32_t, uint32_t>, size_t> faceOfEdge;
    for (size_t f = 0; f < tris.size(); ++f)
        for (int k = 0; k < 3; ++k) faceOfEdge[{tris[f][k], tris[f][(k + 1) % 3]}] = f;
    std::vector<size_t> parent(tris.size());
    for (size_t f = 0; f < tris.size(); ++f) parent[f] = f;
    auto find = [&](size_t x) {
        while (parent[x] != x) x = parent[x] = parent[parent[x]];
        return x;
    };
    for (size_t f = 0; f < tris.size(); ++f)
        for (int k = 0; k < 3; ++k) {
            auto it = faceOfEdge.find({tris[f][(k + 1) % 3], tris[f][k]});
            if (it == faceOfEdge.end()) continue;
            const auto& g = tris[it->second];
            uint32_t apex = g[0] + g[1] + g[2] - tris[f][k] - tris[f][(k + 1) % 3];
            if (CGAL::coplanar(point(tris[f][0]), point(tris[f][1]), point(tris[f][2]), point(apex))) {
                size_t a = find(f), b = find(it->second);
                if (a != b) parent[std::max(a, b)] = std::min(a, b);
            }
        }
    std::map<size_t, std::map<uint32_t, uint32_t>> boundary;  // facet -> next vertex along its boundary
    for (size_t f = 0; f < tris.size(); ++f) {
        const size_t root = find(f);
        for (int k = 0; k < 3; ++k) {
            uint32_t u = tris[f][k], v = tris[f][(k + 1) % 3];
            auto it = faceOfEdge.find({v, u});
            if (it != faceOfEdge.end() && find(it->second) == root) continue;  // inner edge
            boundary[root][u] = v;
        }
    }
    std::vector<std::array<uint32_t, 3>> out;
    for (const auto& [root, next] : boundary) {
        const uint32_t start = next.begin()->first;  // smallest vertex of the polygon
        std::vector<uint32_t> loop{start};
        for (uint32_t v = next.at(start); v != start && loop.size() <= next.size(); v = next.at(v)) loop.push_back(v);
        for (size_t k = 1; k + 1 < loop.size(); ++k) out.push_back({loop[0], loop[k], loop[k + 1]});
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
