// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod module (internal): exact minimum distance between triangle meshes, and closest
// point on a mesh, accelerated by a bounding volume hierarchy (BVH) of axis-aligned boxes.
//
// Implements:
// - point-triangle closest point (Ericson, "Real-Time Collision Detection", 2005, 5.1.5),
//   restructured so that degenerate triangles (zero area, repeated vertices) fall back to
//   their edges (point-segment, Ericson 5.1.2) instead of dividing by zero;
// - segment-segment closest points (Ericson 5.1.9), robust for parallel and degenerate
//   (zero-length) segments;
// - triangle-triangle distance = min over the 6 vertex-face and 9 edge-edge pairs, plus an
//   intersection test (an edge of one triangle crossing the other, Ericson 5.3.4 scalar
//   triple products; coplanar overlap by a 2D separating-axis test), giving 0 when the
//   triangles intersect or touch;
// - a BVH of axis-aligned boxes built top-down by binned SAH over triangle centroids
//   (Wald 2007; leaves <= 4 triangles, flattened node array, exact double boxes), and
//   BVH-vs-BVH / point-vs-BVH depth-first traversal, nearer box pair first, pruning pairs
//   whose box distance exceeds the current best (Ericson 6.3.1 "descend larger" rule,
//   6.3.2 informed depth-first traversal).
//
// Units: every length is in the input's world units. Arrays: positions are xyz triples
// (3 * vertexCount doubles), indices are triangle corner triples (3 * triangleCount);
// every point argument/result is 3 doubles.
// Exactness: results are the exact minimum up to double rounding, with one documented
// snap: two triangles whose vertices lie within 1e-12 * (longest edge) of the other's plane
// are treated as coplanar, and report distance 0 when they overlap in that plane.
// Determinism: single-threaded, fixed traversal order; among pairs at equal distance the
// lowest (triangleA, triangleB) pair (original indices) wins, so meshDistance without early
// exit returns bit-for-bit what a brute-force loop over all pairs with
// triangleTriangleDistance would return.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

namespace aggrelod::detail {


/// BVH over a triangle soup. Copies the triangle corners (in leaf order), so the input
/// arrays may be released after build().
class TriangleBvh {
public:
    struct Node {
        double lo[3], hi[3];
        uint32_t first;  ///< leaf: first triangle slot; inner: index of left child (right = first + 1)
        uint32_t count;  ///< leaf: number of triangles (1..4); inner: 0
    };

    /// positions: 3 * vertexCount doubles; indices: 3 * triangleCount, each < vertexCount;
    /// referenced coordinates finite (throws std::invalid_argument otherwise). Rebuilds
    /// from scratch; single-threaded, deterministic.
    void build(const double* positions, size_t vertexCount, const uint32_t* indices,
               size_t triangleCount);
    /// Bounding box of every triangle; lo = +inf, hi = -inf when empty.
    void bounds(double lo[3], double hi[3]) const;
    size_t triangleCount() const { return triangleIndex_.size(); }

    // Internals, read by the queries.
    const std::vector<Node>& nodes() const { return nodes_; }
    /// 9 doubles per slot (corners 0, 1, 2), slots in leaf order.
    const double* slotCorners(uint32_t slot) const { return &corners_[size_t(slot) * 9]; }
    /// Original triangle index of a slot.
    uint32_t slotTriangle(uint32_t slot) const { return triangleIndex_[slot]; }
    /// Largest |coordinate| over all corners (scales rounding tolerances).
    double maxAbsCoordinate() const { return maxAbs_; }

private:
    std::vector<Node> nodes_;
    std::vector<double> corners_;
    std::vector<uint32_t> triangleIndex_;
    double maxAbs_ = 0;
};

struct ClosestPair {
    double distance = std::numeric_limits<double>::infinity();  ///< 0 when the meshes intersect/touch
    double pointA[3] = {0, 0, 0};  ///< closest point on A (equal to pointB when intersecting)
    double pointB[3] = {0, 0, 0};  ///< closest point on B
    uint32_t triangleA = ~0u;      ///< original triangle index in A; ~0u when none found
    uint32_t triangleB = ~0u;
    bool intersecting = false;     ///< distance == 0 (crossing, coplanar overlap or touching)
};

/// Exact minimum distance between two triangle sets (vertex-face, edge-edge, and
/// triangle-triangle intersection -> 0). Surfaces only: a mesh nested inside another one
/// without touching it gets the gap between the surfaces, not 0.
/// Pairs farther than maxDistance are ignored; result.distance = inf (triangles ~0u) when no
/// pair is within maxDistance. If stopBelow > 0, returns as soon as a pair at distance
/// <= stopBelow is found (distance is then <= stopBelow but not necessarily minimal; still
/// deterministic). Otherwise returns the minimum with the lowest (triangleA, triangleB) pair.
ClosestPair meshDistance(const TriangleBvh& a, const TriangleBvh& b,
                         double maxDistance = std::numeric_limits<double>::infinity(),
                         double stopBelow = 0);

struct ClosestPoint {
    double distance = std::numeric_limits<double>::infinity();
    double point[3] = {0, 0, 0};  ///< closest point on the mesh (zeros when none found)
    uint32_t triangle = ~0u;      ///< original triangle index; ~0u when none within maxDistance
};

/// Closest point on the mesh to p (3 doubles); ties -> lowest triangle index.
ClosestPoint closestPoint(const TriangleBvh& bvh, const double p[3],
                          double maxDistance = std::numeric_limits<double>::infinity());

/// Whether some triangle of the mesh lies within `distance` of p (3 doubles), distances
/// computed exactly as closestPoint computes them: true exactly when
/// closestPoint(bvh, p).distance <= distance. Stops at the first such triangle, so it is much
/// quicker than closestPoint when the answer is yes.
bool anyWithin(const TriangleBvh& bvh, const double p[3], double distance);

// ---- Low-level primitives, exposed for tests. Output pointers may be null. ----

/// Distance between triangles (a0,a1,a2) and (b0,b1,b2); outA/outB get the closest points
/// (the same point when intersecting); *intersecting = (result == 0).
double triangleTriangleDistance(const double* a0, const double* a1, const double* a2,
                                const double* b0, const double* b1, const double* b2,
                                double outA[3], double outB[3], bool* intersecting);

/// Distance from p to triangle (a,b,c); out gets the closest point. Ericson 5.1.5.
double pointTriangleDistance(const double* p, const double* a, const double* b,
                             const double* c, double out[3]);

/// Distance between segments p1-q1 and p2-q2; out1/out2 get the closest points, s/t their
/// parameters in [0,1] (out1 = p1 + s (q1 - p1)). Ericson 5.1.9.
double segmentSegmentDistance(const double* p1, const double* q1, const double* p2,
                              const double* q2, double out1[3], double out2[3],
                              double* s = nullptr, double* t = nullptr);

}  // namespace aggrelod::detail
