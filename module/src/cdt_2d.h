// Constrained Delaunay triangulation of a planar point set with constraint segments
// (DESIGN 2.1, 2D; paper Section 3.1). The only place that knows CGAL's 2D triangulation.
#pragma once

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
int orientation2D(const double* a, const double* b, const double* c);

/// CGAL's in-circle test with the symbolic perturbation its Delaunay flips use: 1 when p is
/// inside the circle through the counter-clockwise triangle p0 p1 p2, -1 outside (never 0).
int perturbedSideOfCircle2D(const double* p0, const double* p1, const double* p2, const double* p);

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
    bool build(const std::vector<double>& points, const std::vector<std::pair<size_t, size_t>>& segments,
               Triangulation2D& out, std::string& error, int threadCount = 0);

private:
    struct Impl;
    Impl* impl_;
};

}  // namespace aggrelod::detail
