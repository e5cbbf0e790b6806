// aggrelod module: geometric error of a proxy against the original objects (DESIGN 2.5,
// "Geometric error of a proxy"): both one-sided Hausdorff distances, sampled.
//
// Samples: every vertex, plus a regular barycentric grid on every triangle whose step is at
// most `spacing` (the triangle is cut into n^2 similar sub-triangles, n = ceil(longest edge
// / spacing)), so every surface point lies within `spacing` of a sample and the sampling is
// area-weighted and deterministic. The distance from a point to a surface (or to a solid) is
// 1-Lipschitz in the point, hence the true Hausdorff distance is at most the sampled maximum
// + spacing (ProxyError::bound()).
//
// Directions:
// - proxy -> originals: distance from a proxy sample to the nearest original surface
//   (closest-point BVH query, mesh_distance.h);
// - originals -> proxy: distance from an original sample to the proxy *solid*: 0 when the
//   sample is inside the proxy (an original surface buried in the aggregate's fill is covered
//   by it, not missing), else the distance to the proxy surface. Inside = odd number of
//   crossings of a ray, majority of three rays in fixed directions (robust to a ray grazing
//   an edge or a vertex).
#include "mesh_distance.h"

#include <aggrelod/hierarchy_nodes.h>

#include <algorithm>
#include <cmath>

namespace aggrelod {

double ProxyError::bound() const { return std::max(proxyToOriginals, originalsToProxy) + sampleSpacing; }

namespace {

using detail::TriangleBvh;

/// Number of grid steps along each side of a triangle with longest edge `longest`.
size_t stepsFor(double longest, double spacing) {
    if (!(spacing > 0) || !(longest > spacing)) return 1;
    return static_cast<size_t>(std::ceil(longest / spacing));
}

double longestEdge(const double* a, const double* b, const double* c) {
    auto d = [](const double* p, const double* q) {
        return std::sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) + (p[2] - q[2]) * (p[2] - q[2]));
    };
    return std::max({d(a, b), d(b, c), d(c, a)});
}

/// A triangle mesh in doubles (positions 3 * n, indices 3 * t).
struct Mesh {
    std::vector<double> positions;
    std::vector<uint32_t> indices;
    const double* corner(size_t t, int k) const { return &positions[3 * size_t(indices[3 * t + k])]; }
    size_t triangleCount() const { return indices.size() / 3; }
};

size_t sampleCount(const Mesh& m, double spacing) {
    size_t count = 0;
    for (size_t t = 0; t < m.triangleCount(); ++t) {
        const size_t n = stepsFor(longestEdge(m.corner(t, 0), m.corner(t, 1), m.corner(t, 2)), spacing);
        count += (n + 1) * (n + 2) / 2;
    }
    return count;
}

/// Calls visit(point) for every grid sample of every triangle (vertices included).
template <class Visit>
void forEachSample(const Mesh& m, double spacing, Visit&& visit) {
    for (size_t t = 0; t < m.triangleCount(); ++t) {
        const double *a = m.corner(t, 0), *b = m.corner(t, 1), *c = m.corner(t, 2);
        const size_t n = stepsFor(longestEdge(a, b, c), spacing);
        for (size_t i = 0; i <= n; ++i)
            for (size_t j = 0; i + j <= n; ++j) {
                const double u = double(i) / double(n), v = double(j) / double(n);
                double p[3];
                for (int k = 0; k < 3; ++k) p[k] = a[k] + u * (b[k] - a[k]) + v * (c[k] - a[k]);
                visit(p);
            }
    }
}

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

}  // namespace

ProxyError measureProxyError(const std::vector<float>& proxyPositions,
                             const std::vector<uint32_t>& proxyIndices,
                             const std::vector<const InputObject*>& originals, double spacing,
                             size_t maxSamplesPerDirection) {
    Mesh proxy, orig;
    proxy.positions.assign(proxyPositions.begin(), proxyPositions.end());
    proxy.indices = proxyIndices;
    for (const InputObject* o : originals) {
        const uint32_t base = static_cast<uint32_t>(orig.positions.size() / 3);
        orig.positions.insert(orig.positions.end(), o->positions.begin(), o->positions.end());
        for (uint32_t i : o->indices) orig.indices.push_back(base + i);
    }
    ProxyError e;
    if (proxy.triangleCount() == 0 || orig.triangleCount() == 0) return e;

    // Widen the spacing until both directions fit the sample budget.
    const size_t budget = std::max<size_t>(maxSamplesPerDirection, 1);
    if (!(spacing > 0)) spacing = 1e-3 * longestEdge(orig.corner(0, 0), orig.corner(0, 1), orig.corner(0, 2));
    for (int round = 0; round < 64; ++round) {
        const size_t most = std::max(sampleCount(proxy, spacing), sampleCount(orig, spacing));
        if (most <= budget) break;
        spacing *= std::max(1.05, std::sqrt(double(most) / double(budget)));
    }
    e.sampleSpacing = spacing;

    TriangleBvh proxyBvh, origBvh;
    proxyBvh.build(proxy.positions.data(), proxy.positions.size() / 3, proxy.indices.data(), proxy.triangleCount());
    origBvh.build(orig.positions.data(), orig.positions.size() / 3, orig.indices.data(), orig.triangleCount());

    forEachSample(proxy, spacing, [&](const double* p) {
        ++e.sampleCount;
        e.proxyToOriginals = std::max(e.proxyToOriginals, detail::closestPoint(origBvh, p).distance);
    });
    forEachSample(orig, spacing, [&](const double* p) {
        ++e.sampleCount;
        const double d = detail::closestPoint(proxyBvh, p).distance;
        // Only a sample that would raise the maximum needs the (costlier) inside test.
        if (d > e.originalsToProxy && !insideSolid(proxyBvh, p)) e.originalsToProxy = d;
    });
    return e;
}

}  // namespace aggrelod
