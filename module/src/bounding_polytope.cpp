// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod module: few-faced enclosing polytopes of a convex hull (docs/design.md §2.6).
//
// Outer polyhedral approximation by cutting planes (the cutting variant of Kamenev's method
// of refined estimates; see Lotov, Bushenkov, Kamenev, "Interactive Decision Maps", 2004,
// chapter 8): start from a polytope bounded by supporting planes of the body, then cut off
// the polytope's vertex farthest from the body with the body's supporting plane at the point
// of the body nearest to that vertex. Every polytope of the sequence is an intersection of
// supporting half-spaces, so it encloses the body; the Hausdorff distance to the body is the
// largest vertex distance (the distance to a convex set is convex, so its maximum over a
// polytope is at a vertex). Where edge collapses of a progressive hull stop at a few dozen
// triangles, this goes down to a tetrahedron: the coarsest versions of a proxy.
//
// The polytope is kept as its planes and the points where three of them meet without
// violating the others: a few dozen planes at most, so this is cheap and cannot lose a vertex
// to rounding the way polygon clipping can.
#include "bounding_polytope.h"

#include "convex_hull.h"
#include "mesh_distance.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <tuple>

namespace aggrelod::detail {
namespace {

using V3 = std::array<double, 3>;

V3 sub(const V3& a, const V3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
double dot(const V3& a, const V3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
V3 cross(const V3& a, const V3& b) {
    return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double norm(const V3& a) { return std::sqrt(dot(a, a)); }

struct Plane {
    V3 normal;      ///< unit, outward
    double offset;  ///< the polytope lies in normal . x <= offset
};

/// A convex polytope as its half-spaces and its vertices. A vertex is where three planes
/// meet and no plane is violated by more than `tolerance`; adding a plane keeps the vertices
/// on its inner side and adds those on it (O(planes^3)), so no polygon bookkeeping can lose
/// a vertex. Vertices closer than the weld distance count as one.
class Polytope {
public:
    Polytope(double tolerance, double weld) : tolerance_(tolerance), weld_(weld) {}

    /// Adds the half-space normal . x <= offset. Until three planes bound a vertex, the
    /// polytope is unbounded and has none.
    void add(const V3& normal, double offset) {
        const Plane cut{normal, offset};
        std::vector<V3> kept;
        for (const V3& v : vertices_)
            if (dot(normal, v) - offset <= tolerance_) kept.push_back(v);
        planes_.push_back(cut);
        const size_t k = planes_.size() - 1;
        for (size_t i = 0; i < k; ++i)
            for (size_t j = i + 1; j < k; ++j) {
                V3 x;
                if (!meet(planes_[i], planes_[j], cut, x) || !feasible(x)) continue;
                bool seen = false;
                for (const V3& v : kept) seen = seen || norm(sub(v, x)) <= weld_;
                if (!seen) kept.push_back(x);
            }
        std::sort(kept.begin(), kept.end());
        vertices_ = std::move(kept);
    }

    const std::vector<V3>& vertices() const { return vertices_; }

private:
    bool feasible(const V3& x) const {
        for (const Plane& p : planes_)
            if (dot(p.normal, x) - p.offset > tolerance_) return false;
        return true;
    }

    /// The point on three planes (Cramer's rule); false when they do not meet in one point.
    static bool meet(const Plane& a, const Plane& b, const Plane& c, V3& x) {
        const V3 bc = cross(b.normal, c.normal), ca = cross(c.normal, a.normal), ab = cross(a.normal, b.normal);
        const double det = dot(a.normal, bc);
        if (!(std::fabs(det) > 1e-9)) return false;
        for (int k = 0; k < 3; ++k) x[k] = (a.offset * bc[k] + b.offset * ca[k] + c.offset * ab[k]) / det;
        return true;
    }

    double tolerance_, weld_;
    std::vector<Plane> planes_;
    std::vector<V3> vertices_;
};

struct Body {
    std::vector<V3> points;  ///< the hull's vertices
    TriangleBvh bvh;
    double margin = 0;

    /// Offset of the supporting plane with this unit normal, pushed out by the margin.
    double support(const V3& normal) const {
        double best = -INFINITY;
        for (const V3& p : points) best = std::max(best, dot(normal, p));
        return best + margin;
    }
};

/// The sequence of one start, appended to out: each polytope, then the next after one cut.
void refine(Polytope polytope, const Body& body, size_t maxVertices, double minDistance,
            std::vector<BoundingPolytope>& out) {
    for (int step = 0; step < 4 * int(maxVertices); ++step) {
        const std::vector<V3>& vertices = polytope.vertices();
        if (vertices.size() < 4 || vertices.size() > maxVertices) return;
        double worst = -1;
        V3 far{0, 0, 0}, near{0, 0, 0};
        for (const V3& v : vertices) {
            const ClosestPoint c = closestPoint(body.bvh, v.data());
            if (c.distance > worst) {
                worst = c.distance;
                far = v;
                near = {c.point[0], c.point[1], c.point[2]};
            }
        }
        BoundingPolytope p;
        p.distanceToHull = worst;
        for (const V3& v : vertices) p.vertices.insert(p.vertices.end(), v.begin(), v.end());
        out.push_back(std::move(p));
        if (!(worst > minDistance) || !(worst > 4 * body.margin)) return;
        V3 normal = sub(far, near);
        const double l = norm(normal);
        for (double& c : normal) c /= l;
        polytope.add(normal, body.support(normal));
    }
}

}  // namespace

std::vector<BoundingPolytope> boundingPolytopes(const std::vector<double>& hullPositions,
                                                const std::vector<uint32_t>& hullTriangles, size_t maxVertices,
                                                double minDistance) {
    std::vector<BoundingPolytope> out;
    Body body;
    V3 lo{INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i + 2 < hullPositions.size(); i += 3) {
        const V3 p{hullPositions[i], hullPositions[i + 1], hullPositions[i + 2]};
        body.points.push_back(p);
        for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], p[k]), hi[k] = std::max(hi[k], p[k]);
    }
    const double diagonal = norm(sub(hi, lo));
    if (body.points.size() < 4 || hullTriangles.size() < 12 || !(diagonal > 0) || !std::isfinite(diagonal)) return out;
    body.margin = 1e-7 * diagonal;
    body.bvh.build(hullPositions.data(), hullPositions.size() / 3, hullTriangles.data(), hullTriangles.size() / 3);

    // Starts: supporting planes normal to the faces of a tetrahedron, a cube and an
    // octahedron (4, 12 and 8 triangles).
    const double s3 = 1 / std::sqrt(3.0);
    std::vector<std::vector<V3>> starts(3);
    starts[0] = {V3{s3, s3, s3}, V3{s3, -s3, -s3}, V3{-s3, s3, -s3}, V3{-s3, -s3, s3}};
    starts[1] = {V3{1, 0, 0}, V3{-1, 0, 0}, V3{0, 1, 0}, V3{0, -1, 0}, V3{0, 0, 1}, V3{0, 0, -1}};
    for (int m = 0; m < 8; ++m) starts[2].push_back(V3{m & 1 ? s3 : -s3, m & 2 ? s3 : -s3, m & 4 ? s3 : -s3});
    for (const std::vector<V3>& directions : starts) {
        Polytope polytope(1e-3 * body.margin, 0.5 * body.margin);
        for (const V3& d : directions) polytope.add(d, body.support(d));
        refine(std::move(polytope), body, maxVertices, minDistance, out);
    }
    // Coarsest first: fewest vertices, then nearest.
    std::stable_sort(out.begin(), out.end(), [](const BoundingPolytope& a, const BoundingPolytope& b) {
        return std::make_tuple(a.vertices.size(), a.distanceToHull) < std::make_tuple(b.vertices.size(), b.distanceToHull);
    });
    return out;
}

bool boundingPolytopeMesh(const BoundingPolytope& polytope, const std::vector<double>& enclosed,
                          std::vector<double>& positions, std::vector<uint32_t>& triangles) {
    positions.clear();
    triangles.clear();
    if (!convexHull3(polytope.vertices, positions, triangles)) return false;
    // Enclosed when adding the points changes no vertex of the hull (exact predicates: a
    // plane through three nearly equal corners cannot be tested in floating point).
    std::vector<double> own, joint, all = polytope.vertices;
    all.insert(all.end(), enclosed.begin(), enclosed.end());
    convexHullVolume(polytope.vertices, &own);
    convexHullVolume(all, &joint);
    if (own.empty() || own != joint) {
        positions.clear();
        triangles.clear();
        return false;
    }
    return true;
}

}  // namespace aggrelod::detail
