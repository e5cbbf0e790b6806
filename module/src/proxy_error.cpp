// aggrelod module: geometric error of a proxy against the original objects (DESIGN 2.5,
// "Geometric error of a proxy"): both one-sided Hausdorff distances, with certified upper
// bounds.
//
// Directions:
// - proxy -> originals: h(p) = distance from a proxy point to the nearest original surface
//   (closest-point BVH query, mesh_distance.h);
// - originals -> proxy: h(p) = distance from an original point to the proxy *solid*: 0 when
//   the point is inside the proxy (an original surface buried in the aggregate's fill is
//   covered by it, not missing), else the distance to the proxy surface. Inside = odd number
//   of crossings of a ray, majority of three rays in fixed directions.
//
// Branch and bound over triangles (in the spirit of Tang et al., "Interactive Hausdorff
// distance computation for general polygonal models", SIGGRAPH 2009): every triangle of the
// measured mesh is a region; at its centroid c, h(c) is a lower bound of the maximum. An
// upper bound of h over the region (ball of radius rho around c holding its corners) is the
// smaller of
//   - h(c) + rho, as h is 1-Lipschitz, and
//   - max over the corners v of dist(v, T), T the target triangle nearest to c: the distance
//     to one triangle is convex, so its maximum over the region is at a corner, and the
//     distance to the whole target is at most the distance to T;
// and 0 for originals -> proxy when c is inside and the ball misses the proxy surface. The
// region with the largest upper bound is split into four (edge midpoints) until it is within
// `tolerance` of the best lower bound or the evaluation budget is spent; the result is the
// largest remaining upper bound: never below the true Hausdorff distance.
#include "mesh_distance.h"

#include <aggrelod/hierarchy_nodes.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <queue>

namespace aggrelod {

double ProxyError::bound() const { return std::max(proxyToOriginals, originalsToProxy); }

namespace {

using detail::TriangleBvh;

/// A triangle mesh in doubles (positions 3 * n, indices 3 * t).
struct Mesh {
    std::vector<double> positions;
    std::vector<uint32_t> indices;
    const double* corner(size_t t, int k) const { return &positions[3 * size_t(indices[3 * t + k])]; }
    size_t triangleCount() const { return indices.size() / 3; }
};

/// Number of triangles of `bvh` crossed by the ray p + t d, t > 0 (Moller-Trumbore).
size_t crossings(const TriangleBvh& bvh, const double p[3], const double d[3]) {
    const auto& nodes = bvh.nodes();
    if (nodes.empty()) return 0;
    double inv[3];
    for (int k = 0; k < 3; ++k) inv[k] = 1.0 / d[k];
    size_t count = 0;
    uint32_t stack[128];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        const TriangleBvh::Node& N = nodes[stack[--top]];
        double tmin = 0, tmax = INFINITY;
        for (int k = 0; k < 3; ++k) {
            double t0 = (N.lo[k] - p[k]) * inv[k], t1 = (N.hi[k] - p[k]) * inv[k];
            if (t0 > t1) std::swap(t0, t1);
            tmin = std::max(tmin, t0);
            tmax = std::min(tmax, t1);
        }
        if (tmin > tmax * (1 + 1e-12) + 1e-300) continue;
        if (N.count == 0) {
            if (top + 2 > 128) continue;  // cannot happen for a SAH tree of < 2^60 triangles
            stack[top++] = N.first;
            stack[top++] = N.first + 1;
            continue;
        }
        for (uint32_t i = 0; i < N.count; ++i) {
            const double* c = bvh.slotCorners(N.first + i);
            double e1[3], e2[3], s[3], q[3], h[3];
            for (int k = 0; k < 3; ++k) {
                e1[k] = c[3 + k] - c[k];
                e2[k] = c[6 + k] - c[k];
                s[k] = p[k] - c[k];
            }
            h[0] = d[1] * e2[2] - d[2] * e2[1];
            h[1] = d[2] * e2[0] - d[0] * e2[2];
            h[2] = d[0] * e2[1] - d[1] * e2[0];
            const double det = e1[0] * h[0] + e1[1] * h[1] + e1[2] * h[2];
            if (det == 0) continue;
            const double u = (s[0] * h[0] + s[1] * h[1] + s[2] * h[2]) / det;
            if (u < 0 || u > 1) continue;
            q[0] = s[1] * e1[2] - s[2] * e1[1];
            q[1] = s[2] * e1[0] - s[0] * e1[2];
            q[2] = s[0] * e1[1] - s[1] * e1[0];
            const double v = (d[0] * q[0] + d[1] * q[1] + d[2] * q[2]) / det;
            if (v < 0 || u + v > 1) continue;
            const double t = (e2[0] * q[0] + e2[1] * q[1] + e2[2] * q[2]) / det;
            if (t > 0) ++count;
        }
    }
    return count;
}

bool insideSolid(const TriangleBvh& bvh, const double p[3]) {
    // Three fixed, unrelated directions (unlikely to be parallel to modelled faces).
    static const double kDirections[3][3] = {
        {0.5773502691896258, 0.5773502691896257, 0.5773502691896259},
        {-0.2672612419124244, 0.8017837257372732, -0.5345224838248488},
        {0.8164965809277261, -0.4082482904638631, -0.4082482904638629}};
    int inside = 0;
    for (const auto& d : kDirections) inside += crossings(bvh, p, d) % 2 == 1;
    return inside >= 2;
}


/// One region of the branch and bound: a triangle (corners), its bounds.
struct Region {
    std::array<double, 9> corners;
    double upper;
    uint64_t order;  ///< creation order: a full tie-break, so the refinement is deterministic
};
struct LowerUpperFirst {
    bool operator()(const Region& a, const Region& b) const {
        return a.upper != b.upper ? a.upper < b.upper : a.order > b.order;
    }
};

struct DirectionResult {
    double lower = 0, upper = 0;
    size_t evaluations = 0;
};

/// Max over the surface `from` of h (distance to `target`'s surface, or to its solid when
/// toSolid), within `tolerance`, spending at most about `budget` evaluations beyond one per
/// triangle. `targetMesh` gives the target triangles' corners by original index.
DirectionResult hausdorffBound(const Mesh& from, const TriangleBvh& target, const Mesh& targetMesh, bool toSolid,
                               double tolerance, size_t budget) {
    DirectionResult r;
    std::priority_queue<Region, std::vector<Region>, LowerUpperFirst> open;
    uint64_t order = 0;
    auto evaluate = [&](const std::array<double, 9>& c) {
        ++r.evaluations;
        double centroid[3], rho = 0;
        for (int k = 0; k < 3; ++k) centroid[k] = (c[k] + c[3 + k] + c[6 + k]) / 3;
        for (int v = 0; v < 3; ++v) {
            const double dx = c[3 * v] - centroid[0], dy = c[3 * v + 1] - centroid[1], dz = c[3 * v + 2] - centroid[2];
            rho = std::max(rho, std::sqrt(dx * dx + dy * dy + dz * dz));
        }
        const detail::ClosestPoint cp = detail::closestPoint(target, centroid);
        const double d = cp.distance;
        double upper = d + rho;
        if (cp.triangle != ~0u) {
            const double* a = targetMesh.corner(cp.triangle, 0);
            const double* b = targetMesh.corner(cp.triangle, 1);
            const double* t = targetMesh.corner(cp.triangle, 2);
            double corners = 0, q[3];
            for (int v = 0; v < 3; ++v) corners = std::max(corners, detail::pointTriangleDistance(&c[3 * v], a, b, t, q));
            upper = std::min(upper, corners);
        }
        double h = d;
        if (toSolid && (d > rho || d > r.lower)) {
            const bool inside = insideSolid(target, centroid);
            if (inside) h = 0;
            if (inside && d > rho) upper = 0;  // the ball lies inside the solid
        }
        r.lower = std::max(r.lower, h);
        if (upper > r.lower + tolerance) open.push(Region{c, upper, order++});
        else r.upper = std::max(r.upper, upper);
    };
    for (size_t t = 0; t < from.triangleCount(); ++t) {
        std::array<double, 9> c;
        for (int v = 0; v < 3; ++v)
            for (int k = 0; k < 3; ++k) c[size_t(3 * v + k)] = from.corner(t, v)[k];
        evaluate(c);
    }
    const size_t limit = r.evaluations + budget;
    while (!open.empty() && open.top().upper > r.lower + tolerance && r.evaluations + 4 <= limit) {
        const Region g = open.top();
        open.pop();
        const double* c = g.corners.data();
        double m[3][3];  // edge midpoints 01, 12, 20
        for (int k = 0; k < 3; ++k) {
            m[0][k] = 0.5 * (c[k] + c[3 + k]);
            m[1][k] = 0.5 * (c[3 + k] + c[6 + k]);
            m[2][k] = 0.5 * (c[6 + k] + c[k]);
        }
        auto tri = [](const double* p, const double* q, const double* s) {
            return std::array<double, 9>{p[0], p[1], p[2], q[0], q[1], q[2], s[0], s[1], s[2]};
        };
        evaluate(tri(c, m[0], m[2]));
        evaluate(tri(m[0], c + 3, m[1]));
        evaluate(tri(m[2], m[1], c + 6));
        evaluate(tri(m[0], m[1], m[2]));
    }
    // What is left open keeps its upper bound.
    while (!open.empty()) {
        r.upper = std::max(r.upper, open.top().upper);
        open.pop();
    }
    r.upper = std::max(r.upper, r.lower);
    return r;
}

}  // namespace

ProxyError measureProxyError(const std::vector<float>& proxyPositions,
                             const std::vector<uint32_t>& proxyIndices,
                             const std::vector<const InputObject*>& originals, double tolerance,
                             size_t maxRefinementsPerDirection) {
    Mesh proxy, orig;
    proxy.positions.assign(proxyPositions.begin(), proxyPositions.end());
    proxy.indices = proxyIndices;
    for (const InputObject* o : originals) {
        const uint32_t base = static_cast<uint32_t>(orig.positions.size() / 3);
        orig.positions.insert(orig.positions.end(), o->positions.begin(), o->positions.end());
        for (uint32_t i : o->indices) orig.indices.push_back(base + i);
    }
    ProxyError e;
    e.tolerance = tolerance;
    if (orig.triangleCount() == 0) return e;
    if (proxy.triangleCount() == 0) {
        // Nothing drawn in place of the originals: they vanish, an error as large as their
        // extent (the diagonal of their box), so the node is used only when all of it is
        // below the tolerance on screen.
        double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (size_t i = 0; i + 2 < orig.positions.size(); i += 3)
            for (int k = 0; k < 3; ++k) {
                lo[k] = std::min(lo[k], orig.positions[i + k]);
                hi[k] = std::max(hi[k], orig.positions[i + k]);
            }
        e.originalsToProxy = e.originalsToProxyLower =
            std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) + (hi[2] - lo[2]) * (hi[2] - lo[2]));
        return e;
    }
    TriangleBvh proxyBvh, origBvh;
    proxyBvh.build(proxy.positions.data(), proxy.positions.size() / 3, proxy.indices.data(), proxy.triangleCount());
    origBvh.build(orig.positions.data(), orig.positions.size() / 3, orig.indices.data(), orig.triangleCount());
    const DirectionResult forward = hausdorffBound(proxy, origBvh, orig, false, tolerance, maxRefinementsPerDirection);
    const DirectionResult backward = hausdorffBound(orig, proxyBvh, proxy, true, tolerance, maxRefinementsPerDirection);
    e.proxyToOriginals = forward.upper;
    e.originalsToProxy = backward.upper;
    e.proxyToOriginalsLower = forward.lower;
    e.originalsToProxyLower = backward.lower;
    e.evaluationCount = forward.evaluations + backward.evaluations;
    return e;
}

}  // namespace aggrelod
