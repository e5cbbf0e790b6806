// SPDX-License-Identifier: AGPL-3.0-or-later
// Solidification by CGAL 3D Alpha Wrapping (Portaneri et al., "Alpha Wrapping with an
// Offset", ACM TOG 41(4), 2022; CGAL 5.5 `CGAL::alpha_wrap_3`) and by the exact boolean union
// of closed parts (CGAL Polygon Mesh Processing corefinement, Loriot, Tournois, Yaz, "Polygon
// mesh processing", CGAL 5.5 manual). The only translation unit that includes these headers
// (they are heavy: keep them here).
#include "solidify.h"

#include "mesh_distance.h"

#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/corefinement.h>
#include <CGAL/Polygon_mesh_processing/orientation.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/alpha_wrap_3.h>

#include <array>
#include <cmath>
#include <exception>
#include <algorithm>
#include <memory>
#include <numeric>
#include <type_traits>

namespace aggrelod::detail {

namespace {

/// A coordinate as a double; for an exact kernel's lazy number, from its exact value. CGAL's
/// own to_double returns the middle of the interval the number holds whenever that is narrow
/// enough, and the interval narrows once anything has asked for the exact value, which is not
/// the same from one process to the next: the same union came out with other last bits.
template <class FT>
double coordinate(const FT& x) {
    if constexpr (std::is_same_v<FT, double>) return x;
    else return CGAL::to_double(x.exact());
}

/// Vertices and triangles of a triangle Surface_mesh without removed elements, in index
/// order (deterministic: the order the algorithm created them). False on a face that is not
/// a triangle.
template <class Mesh>
bool meshToArrays(const Mesh& mesh, std::vector<double>& outPositions, std::vector<uint32_t>& outTriangles) {
    outPositions.clear();
    outTriangles.clear();
    outPositions.reserve(3 * mesh.number_of_vertices());
    std::vector<uint32_t> index(mesh.num_vertices(), UINT32_MAX);
    uint32_t next = 0;
    for (typename Mesh::Vertex_index v : mesh.vertices()) {
        const auto& p = mesh.point(v);
        index[v.idx()] = next++;
        outPositions.push_back(coordinate(p.x()));
        outPositions.push_back(coordinate(p.y()));
        outPositions.push_back(coordinate(p.z()));
    }
    outTriangles.reserve(3 * mesh.number_of_faces());
    for (typename Mesh::Face_index f : mesh.faces()) {
        size_t corners = 0;
        for (typename Mesh::Vertex_index v : CGAL::vertices_around_face(mesh.halfedge(f), mesh))
            if (corners++ < 3) outTriangles.push_back(index[v.idx()]);
        if (corners != 3) {
            outPositions.clear();
            outTriangles.clear();
            return false;
        }
    }
    return true;
}

/// CGAL's triangle-soup oracle with two quick answers in front of its own queries, which
/// are most of a wrap's time: "does this ball meet the input?" (asked for every gate, almost
/// always of a ball far from it) and "does this tetrahedron meet the input?" (mostly not).
/// A query is answered here only when a double-precision test decides it with a margin far
/// above its rounding error; every other one goes to CGAL's exact one. The answers are
/// therefore CGAL's. With `constructions`, the closest points and the offset surface's
/// crossings (the Steiner points) are computed on this oracle's BVH too: the same points up to
/// rounding, so the wrap is no longer CGAL's bit for bit (see WrapOracle).
template <class Kernel>
class QuickOracle : public CGAL::Alpha_wraps_3::internal::Triangle_soup_oracle<Kernel> {
    using Base = CGAL::Alpha_wraps_3::internal::Triangle_soup_oracle<Kernel>;
    using Ball = CGAL::Alpha_wraps_3::internal::Ball_3<Kernel>;

public:
    /// points: the input's corners; faces: its triangles, as given to add_triangle_soup.
    /// constructions: closest points and offset crossings on this oracle's BVH (else CGAL's).
    QuickOracle(double alpha, const std::vector<double>& positions, const std::vector<typename Kernel::Point_3>& points,
                const std::vector<std::array<size_t, 3>>& faces, bool constructions)
        : Base(alpha, Kernel()), constructions_(constructions) {
        // The same triangles as CGAL's soup: it leaves out the exactly degenerate ones (CGAL
        // tests each original triangle; its splitting only makes tighter boxes).
        std::vector<uint32_t> kept, forBalls;
        kept.reserve(3 * faces.size());
        forBalls.reserve(3 * faces.size());
        const typename Kernel::Collinear_3 collinear = Kernel().collinear_3_object();
        for (const auto& f : faces) {
            if (collinear(points[f[0]], points[f[1]], points[f[2]])) continue;
            for (size_t corner : f) kept.push_back(static_cast<uint32_t>(corner));
            // The point-triangle distance projects along the computed normal, which rounding
            // can tilt on a sliver (corners collinear but for a few ulps): it could then
            // overstate the distance. A sliver is given to the ball query as its three edges,
            // whose distance is exact and overstates the sliver's by at most its width.
            const double* a = &positions[3 * f[0]];
            const double* b = &positions[3 * f[1]];
            const double* c = &positions[3 * f[2]];
            double ab[3], ac[3], bc[3];
            for (int k = 0; k < 3; ++k) {
                ab[k] = b[k] - a[k];
                ac[k] = c[k] - a[k];
                bc[k] = c[k] - b[k];
            }
            const double n[3] = {ab[1] * ac[2] - ab[2] * ac[1], ab[2] * ac[0] - ab[0] * ac[2], ab[0] * ac[1] - ab[1] * ac[0]};
            const double twiceArea = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
            const double lab = std::sqrt(ab[0] * ab[0] + ab[1] * ab[1] + ab[2] * ab[2]);
            const double lac = std::sqrt(ac[0] * ac[0] + ac[1] * ac[1] + ac[2] * ac[2]);
            const double lbc = std::sqrt(bc[0] * bc[0] + bc[1] * bc[1] + bc[2] * bc[2]);
            if (twiceArea > 1e-4 * lab * lac) {
                for (size_t corner : f) forBalls.push_back(static_cast<uint32_t>(corner));
                continue;
            }
            const uint32_t i = static_cast<uint32_t>(f[0]), j = static_cast<uint32_t>(f[1]), k = static_cast<uint32_t>(f[2]);
            forBalls.insert(forBalls.end(), {i, j, i, j, k, j, k, i, k});
            // Its width: twice the area over its longest side (computed area errs by far less
            // than the factor two).
            sliverWidth_ = std::max(sliverWidth_, 2 * twiceArea / std::max(lab, std::max(lac, lbc)) +
                                                      1e-12 * std::max(lab, std::max(lac, lbc)));
        }
        bvh_.build(positions.data(), positions.size() / 3, kept.data(), kept.size() / 3);
        if (forBalls != kept) {
            ballBvh_ = std::make_unique<TriangleBvh>();
            ballBvh_->build(positions.data(), positions.size() / 3, forBalls.data(), forBalls.size() / 3);
        }
        // The tests below err by rounding only (a few ulps of the coordinates): a margin of a
        // billionth of the largest coordinate is far above that.
        margin_ = 1e-9 * bvh_.maxAbsCoordinate();
    }

    template <class Query>
    bool do_intersect(const Query& query) const {
        return Base::do_intersect(query);
    }

    using Point = typename Kernel::Point_3;
    using FT = typename Kernel::FT;

    // CGAL's own tree is slow on closest points (most of a wrap's time on inputs of many
    // triangles: the Steiner points need them). Distances are taken on the BVH with slivers
    // as their edges, whose distances are exact (a sliver's computed normal is mostly
    // rounding).

    /// p's coordinates as doubles.
    static std::array<double, 3> coordinates(const Point& p) {
        return {CGAL::to_double(p.x()), CGAL::to_double(p.y()), CGAL::to_double(p.z())};
    }

    /// The input's closest point to p.
    Point closest_point(const Point& p) const {
        if (!constructions_ || distanceBvh().triangleCount() == 0) return Base::closest_point(p);
        const std::array<double, 3> c = coordinates(p);
        const ClosestPoint nearest = closestPoint(distanceBvh(), c.data());
        return Point(nearest.point[0], nearest.point[1], nearest.point[2]);
    }

    /// The squared distance from p to the input.
    FT squared_distance(const Point& p) const {
        if (!constructions_ || distanceBvh().triangleCount() == 0) return Base::squared_distance(p);
        const std::array<double, 3> c = coordinates(p);
        const double d = closestPoint(distanceBvh(), c.data()).distance;
        return d * d;
    }

    /// The first point of segment pq at distance `offset` from the input: CGAL's own search
    /// (Offset_intersection, to within 1 % of the offset as CGAL's oracle asks it), with the
    /// distances from this oracle's BVH.
    bool first_intersection(const Point& p, const Point& q, Point& o, const FT offset) const {
        if (!constructions_ || distanceBvh().triangleCount() == 0) return Base::first_intersection(p, q, o, offset);
        struct Distance {
            const TriangleBvh* bvh;
            FT operator()(const Point& x) const { return closestPoint(*bvh, coordinates(x).data()).distance; }
        };
        CGAL::Alpha_wraps_3::internal::Offset_intersection<Kernel, Distance> search(Distance{&distanceBvh()}, offset,
                                                                                   1e-2 * offset, 1);
        return search.first_intersection(p, q, o);
    }

    bool do_intersect(const Ball& ball) const {
        const auto& sphere = ball.boundary();
        const std::array<double, 3> c = coordinates(sphere.center());
        const double r = std::sqrt(CGAL::to_double(sphere.squared_radius()));
        const double m = margin_ + 1e-9 * (r + std::fabs(c[0]) + std::fabs(c[1]) + std::fabs(c[2]));
        // Slivers' edges stand in for them: nothing within r + margin + their width means
        // nothing within r; an edge point within r - margin is a point of the input.
        const ClosestPoint nearest = closestPoint(distanceBvh(), c.data(), r + m + sliverWidth_);
        if (nearest.triangle == ~0u) return false;
        if (nearest.distance < r - m) return true;
        return Base::do_intersect(ball);
    }

    template <class K2>
    bool do_intersect(const CGAL::Alpha_wraps_3::internal::Tetrahedron_with_outside_info<K2>& tet) const {
        // False when every input triangle near the tetrahedron is apart from the solid
        // tetrahedron by a separating axis with room to spare (then none meets a face of it or
        // lies inside it: CGAL's answer is false too); true when one surely meets it as CGAL
        // counts it (surelyMeets); else CGAL's test.
        double v[4][3];
        for (int i = 0; i < 4; ++i)
            for (int k = 0; k < 3; ++k) v[i][k] = CGAL::to_double(tet.m_tet[i][k]);
        double lo[3], hi[3];
        double scale = bvh_.maxAbsCoordinate();
        for (int k = 0; k < 3; ++k) {
            lo[k] = std::min(std::min(v[0][k], v[1][k]), std::min(v[2][k], v[3][k]));
            hi[k] = std::max(std::max(v[0][k], v[1][k]), std::max(v[2][k], v[3][k]));
            scale = std::max(scale, std::max(std::fabs(lo[k]), std::fabs(hi[k])));
        }
        const double m = 1e-9 * scale;
        for (int k = 0; k < 3; ++k) {
            lo[k] -= m;
            hi[k] += m;
        }
        const std::vector<TriangleBvh::Node>& nodes = bvh_.nodes();
        if (nodes.empty()) return Base::do_intersect(tet);
        thread_local std::vector<uint32_t> stack;
        stack.clear();
        stack.push_back(0);
        bool undecided = false;
        while (!stack.empty()) {
            const TriangleBvh::Node& node = nodes[stack.back()];
            stack.pop_back();
            bool overlaps = true;
            for (int k = 0; k < 3; ++k) overlaps = overlaps && node.lo[k] <= hi[k] && node.hi[k] >= lo[k];
            if (!overlaps) continue;
            if (node.count == 0) {
                stack.push_back(node.first);
                stack.push_back(node.first + 1);
                continue;
            }
            for (uint32_t i = 0; i < node.count; ++i) {
                const double* t = bvh_.slotCorners(node.first + i);
                if (separated(v, t, m)) continue;
                if (surelyMeets(v, tet.m_b, t)) return true;
                undecided = true;
            }
        }
        return undecided ? Base::do_intersect(tet) : false;
    }

private:
    /// The orientation of d against plane abc (the signed volume det(b - a, c - a, d - a)),
    /// or 0 when rounding could change its sign: the determinant errs by a few ulps of the
    /// product of its vectors' lengths (each difference of two doubles is rounded once).
    static double orientation(const double* a, const double* b, const double* c, const double* d) {
        double u[3], w[3], x[3];
        for (int k = 0; k < 3; ++k) {
            u[k] = b[k] - a[k];
            w[k] = c[k] - a[k];
            x[k] = d[k] - a[k];
        }
        const double det = u[0] * (w[1] * x[2] - w[2] * x[1]) - u[1] * (w[0] * x[2] - w[2] * x[0]) +
                           u[2] * (w[0] * x[1] - w[1] * x[0]);
        const double bound = 1e-10 * std::sqrt((u[0] * u[0] + u[1] * u[1] + u[2] * u[2]) *
                                               (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]) *
                                               (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]));
        return std::fabs(det) > bound ? det : 0.0;
    }

    /// Whether segment pq crosses triangle abc through their interiors, decided with room to
    /// spare (false when rounding could matter).
    static bool surelyCrosses(const double* p, const double* q, const double* a, const double* b, const double* c) {
        const double sp = orientation(a, b, c, p), sq = orientation(a, b, c, q);
        if (sp == 0 || sq == 0 || (sp > 0) == (sq > 0)) return false;
        const double s1 = orientation(p, q, a, b), s2 = orientation(p, q, b, c), s3 = orientation(p, q, c, a);
        if (s1 == 0 || s2 == 0 || s3 == 0) return false;
        return (s1 > 0) == (s2 > 0) && (s2 > 0) == (s3 > 0);
    }

    /// Whether input triangle t (9 doubles) meets tetrahedron v as CGAL's query counts it, with
    /// room to spare: t crosses a face not shared with an outside cell (`outside` bit i: face i,
    /// opposite vertex i), or t lies inside. CGAL splits input triangles into smaller pieces
    /// and asks each piece whether it meets such a face or has its first corner inside: a
    /// crossing with room to spare lies in some piece, and a triangle inside has every piece
    /// inside, so CGAL's answer is true too.
    template <class Bits>
    static bool surelyMeets(const double v[4][3], const Bits& outside, const double* t) {
        bool inside = true;
        for (int i = 0; i < 4 && inside; ++i) {
            const double* a = v[(i + 1) & 3];
            const double* b = v[(i + 2) & 3];
            const double* c = v[(i + 3) & 3];
            const double own = orientation(a, b, c, v[i]);
            for (int corner = 0; corner < 3 && inside; ++corner) {
                const double o = orientation(a, b, c, t + 3 * corner);
                inside = own != 0 && o != 0 && (o > 0) == (own > 0);
            }
        }
        if (inside) return true;
        for (int i = 0; i < 4; ++i) {
            if (outside.test(i)) continue;
            const double* a = v[(i + 1) & 3];
            const double* b = v[(i + 2) & 3];
            const double* c = v[(i + 3) & 3];
            const double* face[3] = {a, b, c};
            for (int e = 0; e < 3; ++e) {
                if (surelyCrosses(t + 3 * e, t + 3 * ((e + 1) % 3), a, b, c)) return true;
                if (surelyCrosses(face[e], face[(e + 1) % 3], t, t + 3, t + 6)) return true;
            }
        }
        return false;
    }

    /// A separating axis between tetrahedron v and triangle t (9 doubles) with a gap wider
    /// than `margin` (a length): the face normals of both and the cross products of their
    /// edges (Gottschalk et al. 1996; Ericson, Real-Time Collision Detection, 5.2.1).
    static bool separated(const double v[4][3], const double* t, double margin) {
        auto sub = [](const double* a, const double* b, double* out) {
            for (int k = 0; k < 3; ++k) out[k] = a[k] - b[k];
        };
        auto cross = [](const double* a, const double* b, double* out) {
            out[0] = a[1] * b[2] - a[2] * b[1];
            out[1] = a[2] * b[0] - a[0] * b[2];
            out[2] = a[0] * b[1] - a[1] * b[0];
        };
        auto apart = [&](const double* n) {
            const double length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
            if (!(length > 0)) return false;
            double tetLo = INFINITY, tetHi = -INFINITY, triLo = INFINITY, triHi = -INFINITY;
            for (int i = 0; i < 4; ++i) {
                const double d = n[0] * v[i][0] + n[1] * v[i][1] + n[2] * v[i][2];
                tetLo = std::min(tetLo, d);
                tetHi = std::max(tetHi, d);
            }
            for (int i = 0; i < 3; ++i) {
                const double d = n[0] * t[3 * i] + n[1] * t[3 * i + 1] + n[2] * t[3 * i + 2];
                triLo = std::min(triLo, d);
                triHi = std::max(triHi, d);
            }
            const double gap = margin * length;
            return triLo > tetHi + gap || tetLo > triHi + gap;
        };
        static const int faces[4][3] = {{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}};
        static const int edges[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
        double a[3], b[3], n[3];
        for (const auto& f : faces) {
            sub(v[f[1]], v[f[0]], a);
            sub(v[f[2]], v[f[0]], b);
            cross(a, b, n);
            if (apart(n)) return true;
        }
        double triEdges[3][3];
        sub(t + 3, t, triEdges[0]);
        sub(t + 6, t + 3, triEdges[1]);
        sub(t, t + 6, triEdges[2]);
        cross(triEdges[0], triEdges[1], n);
        if (apart(n)) return true;
        for (const auto& e : edges) {
            sub(v[e[1]], v[e[0]], a);
            for (const auto& te : triEdges) {
                cross(a, te, n);
                if (apart(n)) return true;
            }
        }
        return false;
    }

    const TriangleBvh& distanceBvh() const { return ballBvh_ ? *ballBvh_ : bvh_; }

    bool constructions_ = false;           ///< closest points and crossings on the BVH
    TriangleBvh bvh_;                      ///< the input's triangles (tetrahedron queries)
    std::unique_ptr<TriangleBvh> ballBvh_;  ///< the same with slivers as their edges, if any
    double sliverWidth_ = 0;                ///< the widest sliver's width (world units)
    double margin_ = 0;
};

}  // namespace

bool alphaWrap(const std::vector<double>& positions, const std::vector<uint32_t>& triangles, double alpha,
               double offset, std::vector<double>& outPositions, std::vector<uint32_t>& outTriangles,
               std::string& error, WrapOracle oracle) {
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
        if (oracle != WrapOracle::Cgal) {
            // As CGAL::alpha_wrap_3 does it, with the quicker oracle.
            QuickOracle<Kernel> quick(alpha, positions, points, faces, oracle == WrapOracle::Quick);
            quick.add_triangle_soup(points, faces, CGAL::parameters::default_values());
            CGAL::Alpha_wraps_3::internal::Alpha_wrap_3<QuickOracle<Kernel>> wrapper(quick);
            wrapper(alpha, offset, wrap, CGAL::parameters::default_values());
        } else {
            CGAL::alpha_wrap_3(points, faces, alpha, offset, wrap);
        }
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
    if (!meshToArrays(wrap, outPositions, outTriangles)) {
        error = "alpha wrap gave a non-triangle face";
        return false;
    }
    return true;
}

namespace {

/// Vertices sorted by (x, y, z), each triangle rotated to start at its smallest index (its
/// orientation kept), triangles sorted: the same surface always comes out in the same order.
/// Vertices at the same position keep their relative order.
void canonicalOrder(std::vector<double>& positions, std::vector<uint32_t>& triangles) {
    const size_t n = positions.size() / 3;
    std::vector<uint32_t> order(n);
    std::iota(order.begin(), order.end(), 0u);
    std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
        return std::lexicographical_compare(&positions[3 * a], &positions[3 * a] + 3, &positions[3 * b],
                                            &positions[3 * b] + 3);
    });
    std::vector<uint32_t> newIndex(n);
    std::vector<double> sorted(positions.size());
    for (size_t i = 0; i < n; ++i) {
        newIndex[order[i]] = static_cast<uint32_t>(i);
        std::copy_n(&positions[3 * order[i]], 3, &sorted[3 * i]);
    }
    positions = std::move(sorted);
    std::vector<std::array<uint32_t, 3>> faces(triangles.size() / 3);
    for (size_t f = 0; f < faces.size(); ++f) {
        std::array<uint32_t, 3> t = {newIndex[triangles[3 * f]], newIndex[triangles[3 * f + 1]],
                                     newIndex[triangles[3 * f + 2]]};
        std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
        faces[f] = t;
    }
    std::sort(faces.begin(), faces.end());
    for (size_t f = 0; f < faces.size(); ++f) std::copy_n(faces[f].begin(), 3, &triangles[3 * f]);
}

}  // namespace

bool exactUnion(const std::vector<const std::vector<double>*>& positions,
                const std::vector<const std::vector<uint32_t>*>& triangles, std::vector<double>& outPositions,
                std::vector<uint32_t>& outTriangles, std::string& error) {
    namespace PMP = CGAL::Polygon_mesh_processing;
    using Kernel = CGAL::Exact_predicates_exact_constructions_kernel;
    using Point = Kernel::Point_3;
    using Mesh = CGAL::Surface_mesh<Point>;
    outPositions.clear();
    outTriangles.clear();
    if (positions.empty() || positions.size() != triangles.size()) {
        error = "no parts to unite";
        return false;
    }
    try {
        Mesh result;
        for (size_t part = 0; part < positions.size(); ++part) {
            const std::vector<double>& p = *positions[part];
            const std::vector<uint32_t>& t = *triangles[part];
            const size_t n = p.size() / 3;
            std::vector<Point> points;
            points.reserve(n);
            for (size_t i = 0; i < n; ++i) {
                if (!std::isfinite(p[3 * i]) || !std::isfinite(p[3 * i + 1]) || !std::isfinite(p[3 * i + 2])) {
                    error = "a coordinate is not finite";
                    return false;
                }
                points.emplace_back(p[3 * i], p[3 * i + 1], p[3 * i + 2]);
            }
            std::vector<std::array<size_t, 3>> faces;
            faces.reserve(t.size() / 3);
            for (size_t k = 0; k + 2 < t.size(); k += 3) {
                if (t[k] >= n || t[k + 1] >= n || t[k + 2] >= n) {
                    error = "triangle index out of range";
                    return false;
                }
                faces.push_back({t[k], t[k + 1], t[k + 2]});
            }
            Mesh mesh;
            if (!PMP::is_polygon_soup_a_polygon_mesh(faces)) {
                error = "part " + std::to_string(part) + " is not a manifold mesh";
                return false;
            }
            PMP::polygon_soup_to_polygon_mesh(points, faces, mesh);
            // Corefinement needs parts that bound a volume and do not cross themselves.
            if (!CGAL::is_closed(mesh) || PMP::does_self_intersect(mesh) || !PMP::does_bound_a_volume(mesh)) {
                error = "part " + std::to_string(part) + " crosses itself or bounds no volume";
                return false;
            }
            if (part == 0) {
                result = std::move(mesh);
                continue;
            }
            Mesh united;
            if (!PMP::corefine_and_compute_union(result, mesh, united)) {
                error = "the union is not a manifold surface (parts touch along an edge or at a point)";
                return false;
            }
            result = std::move(united);
        }
        result.collect_garbage();
        if (!meshToArrays(result, outPositions, outTriangles)) {
            error = "the union has a non-triangle face";
            return false;
        }
        canonicalOrder(outPositions, outTriangles);
    } catch (const std::exception& e) {
        error = std::string("boolean union failed: ") + e.what();
        outPositions.clear();
        outTriangles.clear();
        return false;
    }
    return true;
}

}  // namespace aggrelod::detail
