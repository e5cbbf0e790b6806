// SPDX-License-Identifier: AGPL-3.0-or-later
// Constrained Delaunay triangulation of a planar point set with constraint segments
// (docs/design.md §2.1, 2D; paper Section 3.1). The only place that knows CGAL's 2D triangulation.
#pragma once

#include <atomic>
#include <cmath>
#include <cstddef>
#include <string>
#include <utility>
#include <vector>

namespace aggrelod::detail {

/// Flat triangulation of the convex hull of the input points.
struct Triangulation2D {
    std::vector<double> points;     ///< 2 * vertexCount, x y pairs
    std::vector<int> vertexInput;   ///< per vertex: index of an input point at the same place (the smallest), -1 for a Steiner point
    std::vector<int> inputVertex;   ///< per input point: its vertex
    std::vector<int> faces;         ///< 3 * faceCount vertex indices, counter-clockwise
    std::vector<int> neighbors;     ///< 3 * faceCount: face across the edge opposite corner i, -1 outside the hull
    std::vector<char> constrained;  ///< 3 * faceCount: edge opposite corner i lies on a constraint
    size_t vertexCount() const { return points.size() / 2; }
    size_t faceCount() const { return faces.size() / 3; }
};

/// New vertices on one constraint segment of the build() input, from point `from` to `to`
/// (inserted by insertSplitPoints2D, steiner_2d.h).
struct ConstraintSplit {
    size_t from = 0, to = 0;     ///< indices of build() input points
    std::vector<double> points;  ///< x y pairs, in order from `from` to `to`
};

/// CGAL's exact orientation of the triangle a b c (x y pairs): 1 counter-clockwise, -1
/// clockwise, 0 collinear.
int exactOrientation2D(const double* a, const double* b, const double* c);

/// CGAL's in-circle test with the symbolic perturbation its Delaunay flips use: 1 when p is
/// inside the circle through the counter-clockwise triangle p0 p1 p2, -1 outside (never 0).
int exactPerturbedSideOfCircle2D(const double* p0, const double* p1, const double* p2, const double* p);

/// The same as exactOrientation2D: the determinant in doubles when its sign is certain (the
/// error bound of Shewchuk's orient2d, "Adaptive Precision Floating-Point Arithmetic and Fast
/// Robust Geometric Predicates", 1997), else the exact predicate.
inline int orientation2D(const double* a, const double* b, const double* c) {
    constexpr double epsilon = 0x1p-53;
    constexpr double bound = (3.0 + 16.0 * epsilon) * epsilon;
    const double left = (b[0] - a[0]) * (c[1] - a[1]), right = (b[1] - a[1]) * (c[0] - a[0]);
    const double det = left - right, error = bound * (std::fabs(left) + std::fabs(right));
    if (det > error) return 1;
    if (det < -error) return -1;
    return exactOrientation2D(a, b, c);
}

/// The same as exactPerturbedSideOfCircle2D: the determinant in doubles when its sign is
/// certain (Shewchuk's incircle error bound), else the exact, perturbed predicate.
inline int perturbedSideOfCircle2D(const double* a, const double* b, const double* c, const double* d) {
    constexpr double epsilon = 0x1p-53;
    constexpr double bound = (10.0 + 96.0 * epsilon) * epsilon;
    const double adx = a[0] - d[0], ady = a[1] - d[1], bdx = b[0] - d[0], bdy = b[1] - d[1];
    const double cdx = c[0] - d[0], cdy = c[1] - d[1];
    const double bdxcdy = bdx * cdy, cdxbdy = cdx * bdy, cdxady = cdx * ady;
    const double adxcdy = adx * cdy, adxbdy = adx * bdy, bdxady = bdx * ady;
    const double alift = adx * adx + ady * ady, blift = bdx * bdx + bdy * bdy, clift = cdx * cdx + cdy * cdy;
    const double det = alift * (bdxcdy - cdxbdy) + blift * (cdxady - adxcdy) + clift * (adxbdy - bdxady);
    const double permanent = (std::fabs(bdxcdy) + std::fabs(cdxbdy)) * alift + (std::fabs(cdxady) + std::fabs(adxcdy)) * blift +
                             (std::fabs(adxbdy) + std::fabs(bdxady)) * clift;
    const double error = bound * permanent;
    if (det > error) return 1;
    if (det < -error) return -1;
    return exactPerturbedSideOfCircle2D(a, b, c, d);
}

/// A constrained Delaunay triangulation (CGAL's, hidden behind this class).
class ConstrainedTriangulation2D {
public:
    ConstrainedTriangulation2D();
    ~ConstrainedTriangulation2D();
    ConstrainedTriangulation2D(const ConstrainedTriangulation2D&) = delete;
    ConstrainedTriangulation2D& operator=(const ConstrainedTriangulation2D&) = delete;

    /// Triangulates `points` (2 * n, x y pairs) with the segments `segments` (pairs of point
    /// indices) as constraints, all inserted in one batch (spatially sorted). Crossing
    /// constraints are split at their intersections (new Steiner vertices). Duplicate points
    /// become one vertex. Returns false with a message when the triangulator fails (never throws).
    /// threadCount: threads for the export (0 = all cores; same result for any count).
    /// cancel (optional): when another thread sets it, the build stops soon and returns false
    /// with an empty message (the caller no longer wants this triangulation).
    bool build(const std::vector<double>& points, const std::vector<std::pair<size_t, size_t>>& segments,
               Triangulation2D& out, std::string& error, int threadCount = 0, const std::atomic<bool>* cancel = nullptr);

private:
    struct Impl;
    Impl* impl_;
};

}  // namespace aggrelod::detail
