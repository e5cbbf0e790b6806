// SPDX-License-Identifier: AGPL-3.0-or-later
// Solidification by CGAL 3D Alpha Wrapping (Portaneri et al., "Alpha Wrapping with an
// Offset", ACM TOG 41(4), 2022; CGAL 5.5 `CGAL::alpha_wrap_3`). The only translation unit
// that includes the alpha-wrap headers (they are heavy: keep them here).
#include "solidify.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/alpha_wrap_3.h>

#include <array>
#include <cmath>
#include <exception>

namespace aggrelod::detail {

bool alphaWrap(const std::vector<double>& positions, const std::vector<uint32_t>& triangles, double alpha,
               double offset, std::vector<double>& outPositions, std::vector<uint32_t>& outTriangles,
               std::string& error) {
    using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
    using Point = Kernel::Point_3;
    using Mesh = CGAL::Surface_mesh<Point>;
    outPositions.clear();
    outTriangles.clear();
    if (!(alpha > 0) || !(offset > 0) || !std::isfinite(alpha) || !std::isfinite(offset)) {
        error = "alpha and offset must be finite and > 0";
        return false;
    }
    const size_t n = positions.size() / 3;
    if (triangles.empty() || positions.size() % 3 != 0 || triangles.size() % 3 != 0) {
        error = "no triangles to wrap";
        return false;
    }
    std::vector<Point> points;
    points.reserve(n);
    for (size_t i = 0; i < n; ++i) {
        if (!std::isfinite(positions[3 * i]) || !std::isfinite(positions[3 * i + 1]) || !std::isfinite(positions[3 * i + 2])) {
            error = "a coordinate is not finite";
            return false;
        }
        points.emplace_back(positions[3 * i], positions[3 * i + 1], positions[3 * i + 2]);
    }
    std::vector<std::array<size_t, 3>> faces;
    faces.reserve(triangles.size() / 3);
    for (size_t t = 0; t + 2 < triangles.size(); t += 3) {
        if (triangles[t] >= n || triangles[t + 1] >= n || triangles[t + 2] >= n) {
            error = "triangle index out of range";
            return false;
        }
        faces.push_back({triangles[t], triangles[t + 1], triangles[t + 2]});
    }
    Mesh wrap;
    try {
        CGAL::alpha_wrap_3(points, faces, alpha, offset, wrap);
    } catch (const std::exception& e) {
        error = std::string("alpha wrap failed: ") + e.what();
        return false;
    }
    if (!wrap.is_valid(false) || wrap.number_of_faces() == 0) {
        error = "alpha wrap gave no valid surface";
        return false;
    }
    // Surface_mesh indices are dense after a fresh build (no removed elements), in the order
    // the wrap created them: deterministic.
    outPositions.reserve(3 * wrap.number_of_vertices());
    std::vector<uint32_t> index(wrap.num_vertices(), UINT32_MAX);
    uint32_t next = 0;
    for (Mesh::Vertex_index v : wrap.vertices()) {
        const Point& p = wrap.point(v);
        index[v.idx()] = next++;
        outPositions.push_back(p.x());
        outPositions.push_back(p.y());
        outPositions.push_back(p.z());
    }
    outTriangles.reserve(3 * wrap.number_of_faces());
    for (Mesh::Face_index f : wrap.faces()) {
        size_t corners = 0;
        for (Mesh::Vertex_index v : CGAL::vertices_around_face(wrap.halfedge(f), wrap)) {
            if (corners++ < 3) outTriangles.push_back(index[v.idx()]);
        }
        if (corners != 3) {
            error = "alpha wrap gave a non-triangle face";
            outPositions.clear();
            outTriangles.clear();
            return false;
        }
    }
    return true;
}

}  // namespace aggrelod::detail
