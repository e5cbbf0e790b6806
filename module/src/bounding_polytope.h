// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod module (internal): few-faced convex polytopes that enclose a convex hull, for the
// coarsest proxies (docs/design.md §2.6).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace aggrelod::detail {

/// One polytope of a BoundingPolytopes series.
struct BoundingPolytope {
    std::vector<double> vertices;  ///< 3 * vertexCount, world units
    /// Largest distance from a point of the polytope to the hull it encloses (world units;
    /// exact up to rounding: the farthest point of a convex polytope from a convex body is
    /// one of its vertices).
    double distanceToHull = 0;
};

/// Outer approximations of a convex hull by the intersection of a few of its supporting
/// half-spaces, coarsest first: from a tetrahedron and from the axis-aligned box, the
/// polytope's vertex farthest from the hull is cut off again and again by the hull's
/// supporting plane at the point nearest to it, until the polytope has maxVertices vertices
/// or lies within minDistance of the hull.
/// hullPositions: 3 * n doubles, hullTriangles: 3 * m indices of a closed convex mesh (as
/// convexHull3 gives). Every polytope contains every hull vertex with a margin of 1e-7 of
/// the hull's box diagonal. Deterministic. Empty for a degenerate hull.
std::vector<BoundingPolytope> boundingPolytopes(const std::vector<double>& hullPositions,
                                                const std::vector<uint32_t>& hullTriangles, size_t maxVertices,
                                                double minDistance);

/// The closed, outward, triangulated mesh of a polytope (its convex hull), checked to
/// contain every point of `enclosed` (3 * k doubles) strictly. False when the check fails.
bool boundingPolytopeMesh(const BoundingPolytope& polytope, const std::vector<double>& enclosed,
                          std::vector<double>& positions, std::vector<uint32_t>& triangles);

}  // namespace aggrelod::detail
