// SPDX-License-Identifier: AGPL-3.0-or-later
// 3D convex hull (CGAL convex_hull_3, GPL-3+; bake side only). The one place that calls it.
#pragma once

#include <cstdint>
#include <vector>

namespace aggrelod::detail {

/// Convex hull of `points` (3 * n doubles, world units). On success fills hullPositions
/// (3 * m) and hullTriangles (3 * k, outward, closed) and returns true. Returns false when
/// the points span less than 3 dimensions (fewer than 4 points, or all coplanar).
bool convexHull3(const std::vector<double>& points, std::vector<double>& hullPositions,
                 std::vector<uint32_t>& hullTriangles);

/// Volume of the convex hull of `points` (3 * n doubles); 0 when degenerate. When
/// `hullVertices` is given it receives the hull's vertices (3 * m, sorted).
double convexHullVolume(const std::vector<double>& points, std::vector<double>* hullVertices = nullptr);

}  // namespace aggrelod::detail
