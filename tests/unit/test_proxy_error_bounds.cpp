// SPDX-License-Identifier: AGPL-3.0-or-later
// Tests of the certified proxy error bounds (module/src/proxy_error.cpp, docs/design.md §2.5) against
// a brute-force measurement on small cases: a dense barycentric grid on every triangle, exact
// closest points, inside-ness by the generalized winding number (independent of the ray
// parity used by the bound). Each case exercises one of the region bounds: boxes of the
// originals' BVHs dismissed inside the proxy, flat patches and vertex fans where proxy and
// originals share a surface but not a triangulation, inside regions that do not meet the
// proxy surface.
#include <aggrelod/hierarchy_nodes.h>
#include <aggrelod/samples.h>

#include "mesh_distance.h"
#include "proxy_error.h"

#include <gtest/gtest.h>

#include "grid_measure.h"
#include "test_support.h"

#include <algorithm>
#include <cmath>

using namespace aggrelod;

namespace {

using aggrelod::testing::GridMeasured;
using aggrelod::testing::gridMeasure;

/// A generic rotation (about a tilted axis), so that flat faces are flat only up to rounding.
void rotate(std::vector<double>& positions) {
    const double a = 0.7, b = 0.4;
    for (size_t i = 0; i + 2 < positions.size(); i += 3) {
        double x = positions[i], y = positions[i + 1], z = positions[i + 2];
        const double x1 = std::cos(a) * x - std::sin(a) * y, y1 = std::sin(a) * x + std::cos(a) * y;
        const double y2 = std::cos(b) * y1 - std::sin(b) * z, z2 = std::sin(b) * y1 + std::cos(b) * z;
        positions[i] = x1 + 3;
        positions[i + 1] = y2 - 2;
        positions[i + 2] = z2 + 1;
    }
}

std::vector<float> toFloat(const std::vector<double>& p) { return std::vector<float>(p.begin(), p.end()); }


/// The bound is certified (never below the grid measurement) and converged (within the
/// tolerance of the largest distance it found, which it found at a real point).
void expectCertifiedAndConverged(const ProxyError& e, const GridMeasured& m) {
    const double rounding = 1e-9;
    EXPECT_GE(e.proxyToOriginals + rounding, m.proxyToOriginals);
    EXPECT_GE(e.originalsToProxy + rounding, m.originalsToProxy);
    EXPECT_LE(e.proxyToOriginalsLower, e.proxyToOriginals);
    EXPECT_LE(e.originalsToProxyLower, e.originalsToProxy);
    EXPECT_LE(e.proxyToOriginals - e.proxyToOriginalsLower, e.tolerance * (1 + 1e-9));
    EXPECT_LE(e.originalsToProxy - e.originalsToProxyLower, e.tolerance * (1 + 1e-9));
}

/// A prism over a regular n-gon (radius r, z in [z0, z1]) with its caps triangulated as fans
/// from rim vertex 0 (no centre vertex): the same solid as samples::makeCylinder's, another
/// triangulation.
void prismWithRimFans(int n, double r, double z0, double z1, std::vector<double>& pos, std::vector<uint32_t>& idx) {
    pos.clear();
    idx.clear();
    for (int level = 0; level < 2; ++level)
        for (int i = 0; i < n; ++i) {
            const double a = 2 * M_PI * i / n;
            pos.insert(pos.end(), {r * std::cos(a), r * std::sin(a), level ? z1 : z0});
        }
    for (int i = 0; i < n; ++i) {
        const uint32_t a = uint32_t(i), b = uint32_t((i + 1) % n), c = uint32_t(n + (i + 1) % n), d = uint32_t(n + i);
        idx.insert(idx.end(), {a, b, c, a, c, d});
    }
    for (int i = 1; i + 1 < n; ++i) {
        idx.insert(idx.end(), {uint32_t(n), uint32_t(n + i), uint32_t(n + i + 1)});  // top, counter-clockwise from +z
        idx.insert(idx.end(), {0u, uint32_t(i + 1), uint32_t(i)});                 // bottom, seen from -z
    }
}

}  // namespace

TEST(ProxyErrorBounds, SameSurfaceOtherTriangulationConvergesWithinTolerance) {
    // A box with gridded faces against the plain 12-triangle box, both turned by a generic
    // rotation: every original triangle lies on a proxy face, but proxy regions straddle many
    // original edges and vertices (flat-patch bound) and vice versa. Without the patch bounds
    // the branch and bound stops at its budget far above the tolerance.
    InputObject original = samples::makeBox("grid box", {0, 0, 0}, {1.0, 0.7, 0.45}, 0.1);
    InputObject plain = samples::makeBox("plain box", {0, 0, 0}, {1.0, 0.7, 0.45});
    rotate(original.positions);
    rotate(plain.positions);
    const std::vector<float> proxy = toFloat(plain.positions);
    const double tolerance = 1e-3;
    const ProxyError e = measureProxyError(proxy, plain.indices, {&original}, tolerance, 20000);
    EXPECT_LE(e.bound(), tolerance);
    EXPECT_LT(e.evaluationCount, 20000u);  // converged long before the budget
    expectCertifiedAndConverged(e, gridMeasure(proxy, plain.indices, {&original}, 8));
}

TEST(ProxyErrorBounds, CapFansAgainstRimFansConvergeWithinTolerance) {
    // Cylinder caps as fans around a centre vertex (originals) against caps fanned from a rim
    // vertex (proxy): regions around the originals' centre vertex straddle all its triangles
    // (vertex-fan / flat-patch bounds).
    const int n = 12;
    InputObject original = samples::makeCylinder("cylinder", {0, 0, 0}, 0.5, 0.8, n, 3);
    std::vector<double> prism;
    std::vector<uint32_t> prismIndices;
    prismWithRimFans(n, 0.5, 0, 0.8, prism, prismIndices);
    rotate(original.positions);
    rotate(prism);
    const std::vector<float> proxy = toFloat(prism);
    const double tolerance = 1e-3;
    const ProxyError e = measureProxyError(proxy, prismIndices, {&original}, tolerance, 20000);
    EXPECT_LE(e.bound(), tolerance);
    EXPECT_LT(e.evaluationCount, 20000u);
    expectCertifiedAndConverged(e, gridMeasure(proxy, prismIndices, {&original}, 8));
}

TEST(ProxyErrorBounds, BumpySphereProxyMatchesBruteForce) {
    // A proxy crossing the original surface back and forth: vertices of the same UV sphere
    // pushed in and out by up to 6 %. Original points inside the proxy count 0 (solid), the
    // rest their distance; the bound must cover the dense grid and be tight.
    const InputObject sphere = samples::makeUvSphere("sphere", {0.2, -0.1, 0.3}, 1.0, 16, 9);
    std::vector<double> bumpy = sphere.positions;
    for (size_t i = 0; i + 2 < bumpy.size(); i += 3) {
        const double s = 1 + 0.06 * std::sin(1.7 * double(i / 3) + 0.3);
        for (int k = 0; k < 3; ++k) {
            const double c = k == 0 ? 0.2 : (k == 1 ? -0.1 : 0.3);
            bumpy[i + k] = c + s * (bumpy[i + k] - c);
        }
    }
    const std::vector<float> proxy = toFloat(bumpy);
    const double tolerance = 2e-3;
    const ProxyError e = measureProxyError(proxy, sphere.indices, {&sphere}, tolerance, 200000);
    const GridMeasured m = gridMeasure(proxy, sphere.indices, {&sphere}, 12);
    expectCertifiedAndConverged(e, m);
    EXPECT_GT(m.originalsToProxy, 0.01);  // the case really has originals outside the proxy
    EXPECT_GT(m.proxyToOriginals, 0.01);
}

TEST(ProxyErrorBounds, OriginalsInsideABoxProxyAreDismissedByBoxes) {
    // Three objects inside one box proxy, one of them touching its floor: originals -> proxy
    // is 0 (boxes of the originals' BVHs inside the solid, clear of its surface, are
    // dismissed whole; the touching one down to its triangles); proxy -> originals is the
    // farthest box point from them.
    const InputObject a = samples::makeUvSphere("a", {0.3, 0.3, 0.3}, 0.2, 12, 7);
    const InputObject b = samples::makeBox("b", {0.6, 0.1, 0.0}, {0.9, 0.4, 0.3}, 0.1);
    const InputObject c = samples::makeCylinder("c", {0.5, 0.7, 0.2}, 0.15, 0.4, 10, 2);
    const InputObject box = samples::makeBox("proxy", {0, 0, 0}, {1, 1, 1});
    const std::vector<float> proxy = toFloat(box.positions);
    const double tolerance = 2e-3;
    const ProxyError e = measureProxyError(proxy, box.indices, {&a, &b, &c}, tolerance, 200000);
    EXPECT_LE(e.originalsToProxy, tolerance);
    expectCertifiedAndConverged(e, gridMeasure(proxy, box.indices, {&a, &b, &c}, 8));
    EXPECT_GT(e.proxyToOriginals, 0.5);  // the far top corners
    // Fewer evaluations than original triangles: whole objects dismissed at once.
    const size_t originalTriangles = (a.indices.size() + b.indices.size() + c.indices.size()) / 3;
    const ProxyError shrunk = measureProxyError(proxy, box.indices, {&a, &c}, tolerance, 200000);
    EXPECT_LT(shrunk.evaluationCount, originalTriangles);
}

TEST(ProxyErrorBounds, EnclosureOfAConvexSolidIsMeasuredAtItsCorners) {
    // A UV sphere (flat only up to rounding after the rotation) is a convex solid: the distance
    // to it is convex, so over an enclosing proxy it is largest at a corner. The corner bound
    // must cover the dense grid and agree with the branch and bound run on the same proxy.
    InputObject sphere = samples::makeUvSphere("sphere", {0, 0, 0}, 1.0, 24, 13);
    rotate(sphere.positions);
    detail::PreparedOriginal prepared;
    detail::prepareOriginal(sphere, prepared);
    ASSERT_TRUE(prepared.convexSolid);
    // Enclosure: an octahedron around the sphere (vertices at sqrt(3) radii, faces tangent).
    std::vector<double> octa;
    const double r = std::sqrt(3.0) * 1.001, c[3] = {3, -2, 1};  // centre of the rotated sphere
    for (int axis = 0; axis < 3; ++axis)
        for (double s : {1.0, -1.0}) {
            double v[3] = {c[0], c[1], c[2]};
            v[axis] += s * r;
            octa.insert(octa.end(), v, v + 3);
        }
    const std::vector<uint32_t> octaIndices = {0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5};
    const std::vector<float> proxy = toFloat(octa);
    detail::ProxyMeasureOptions enclosure;
    enclosure.enclosesOriginals = true;
    const double tolerance = 1e-3;
    const ProxyError corners = detail::measureProxyErrorPrepared(proxy, octaIndices, {&prepared}, tolerance, 200000, enclosure);
    EXPECT_LT(corners.evaluationCount, 10u);  // one closest point per corner
    const GridMeasured m = gridMeasure(proxy, octaIndices, {&sphere}, 24);
    EXPECT_GE(corners.proxyToOriginals + 1e-9, m.proxyToOriginals);
    prepared.convexSolid = false;  // the same proxy through the branch and bound
    const ProxyError refined = detail::measureProxyErrorPrepared(proxy, octaIndices, {&prepared}, tolerance, 200000, enclosure);
    EXPECT_NEAR(corners.proxyToOriginals, refined.proxyToOriginals, tolerance);
    EXPECT_GT(corners.proxyToOriginals, 0.5);  // the octahedron's corners: about 0.73 radii out
}

TEST(ProxyErrorBounds, ConvexSolidsAreToldFromOthers) {
    auto convex = [](const InputObject& o) {
        detail::PreparedOriginal p;
        detail::prepareOriginal(o, p);
        return p.convexSolid;
    };
    EXPECT_TRUE(convex(samples::makeBox("box", {0, 0, 0}, {1, 2, 3}, 0.25)));
    EXPECT_TRUE(convex(samples::makeCylinder("cylinder", {0, 0, 0}, 0.5, 2, 16, 3)));
    // A vase with a waist is not convex; nor are two boxes in one object, nor an open box.
    EXPECT_FALSE(convex(samples::makeLathe("vase", {0, 0, 0}, {{0.5, 0}, {0.2, 0.5}, {0.5, 1}}, 16)));
    InputObject two = samples::makeBox("a", {0, 0, 0}, {1, 1, 1});
    const InputObject second = samples::makeBox("b", {2, 0, 0}, {3, 1, 1});
    const uint32_t base = uint32_t(two.positions.size() / 3);
    two.positions.insert(two.positions.end(), second.positions.begin(), second.positions.end());
    for (uint32_t i : second.indices) two.indices.push_back(base + i);
    EXPECT_FALSE(convex(two));
    InputObject open = samples::makeBox("open", {0, 0, 0}, {1, 1, 1});
    open.indices.resize(open.indices.size() - 3);
    EXPECT_FALSE(convex(open));
}

TEST(ProxyErrorBounds, TriangleBoundsReusedAcrossProxiesStayCertified) {
    // Two proxies of one original sharing most of their triangles: the second measurement
    // takes the shared triangles' bounds from the cache, evaluates fewer regions and is
    // still certified against the dense grid.
    const InputObject sphere = samples::makeUvSphere("sphere", {0.2, -0.1, 0.3}, 1.0, 16, 9);
    detail::PreparedOriginal prepared;
    detail::prepareOriginal(sphere, prepared);
    prepared.convexSolid = false;  // measure by branch and bound
    auto scaled = [&](double s, size_t upTo) {
        std::vector<double> p = sphere.positions;
        for (size_t i = 0; i + 2 < p.size() && i < 3 * upTo; i += 3) {
            const double centre[3] = {0.2, -0.1, 0.3};
            for (int k = 0; k < 3; ++k) p[i + k] = centre[k] + s * (p[i + k] - centre[k]);
        }
        return toFloat(p);
    };
    const std::vector<float> first = scaled(1.05, SIZE_MAX);
    std::vector<float> second = first;  // the same, with its top vertices pushed out further
    const std::vector<float> further = scaled(1.08, SIZE_MAX);
    std::copy(further.begin(), further.begin() + 3 * 20, second.begin());
    const double tolerance = 2e-3;
    detail::TriangleBoundCache cache;
    detail::ProxyMeasureOptions options;
    options.cache = &cache;
    detail::measureProxyErrorPrepared(first, sphere.indices, {&prepared}, tolerance, 200000, options);
    const size_t cached = cache.bounds.size();
    EXPECT_EQ(cached, sphere.indices.size() / 3);
    const ProxyError withCache = detail::measureProxyErrorPrepared(second, sphere.indices, {&prepared}, tolerance, 200000, options);
    const ProxyError without = detail::measureProxyErrorPrepared(second, sphere.indices, {&prepared}, tolerance, 200000);
    EXPECT_LT(withCache.evaluationCount, without.evaluationCount);
    const GridMeasured m = gridMeasure(second, sphere.indices, {&sphere}, 12);
    EXPECT_GE(withCache.proxyToOriginals + 1e-9, m.proxyToOriginals);
    EXPECT_NEAR(withCache.proxyToOriginals, without.proxyToOriginals, tolerance);
}

TEST(ProxyErrorBounds, EnclosureOfConvexObjectsUsesTheirCornerBounds) {
    // Two coarse spheres, each wrapped by a finer sphere 4 % larger, as one proxy of two
    // shells: every proxy region lies near the largest distance, over curved originals. The
    // largest corner distance to the nearest convex object bounds the distance over a region,
    // so such regions need no refinement down to the tolerance. Certified against the dense
    // grid, as tight as the plain branch and bound, with far fewer evaluations.
    const InputObject left = samples::makeUvSphere("left", {0, 0, 0}, 1.0, 12, 7);
    const InputObject right = samples::makeUvSphere("right", {3, 0.5, 0}, 0.8, 12, 7);
    const InputObject wrapLeft = samples::makeUvSphere("wrap left", {0, 0, 0}, 1.04, 20, 11);
    const InputObject wrapRight = samples::makeUvSphere("wrap right", {3, 0.5, 0}, 0.84, 20, 11);
    std::vector<double> both = wrapLeft.positions;
    std::vector<uint32_t> bothIndices = wrapLeft.indices;
    const uint32_t base = uint32_t(both.size() / 3);
    both.insert(both.end(), wrapRight.positions.begin(), wrapRight.positions.end());
    for (uint32_t i : wrapRight.indices) bothIndices.push_back(base + i);
    const std::vector<float> proxy = toFloat(both);
    detail::PreparedOriginal a, b;
    detail::prepareOriginal(left, a);
    detail::prepareOriginal(right, b);
    ASSERT_TRUE(a.convexSolid && b.convexSolid);
    detail::ProxyMeasureOptions enclosure;
    enclosure.enclosesOriginals = true;
    const double tolerance = 1e-4;
    const ProxyError convex = detail::measureProxyErrorPrepared(proxy, bothIndices, {&a, &b}, tolerance, 200000, enclosure);
    a.convexSolid = b.convexSolid = false;
    const ProxyError plain = detail::measureProxyErrorPrepared(proxy, bothIndices, {&a, &b}, tolerance, 200000, enclosure);
    const GridMeasured m = gridMeasure(proxy, bothIndices, {&left, &right}, 16);
    EXPECT_GE(convex.proxyToOriginals + 1e-9, m.proxyToOriginals);
    EXPECT_NEAR(convex.proxyToOriginals, plain.proxyToOriginals, tolerance);
    EXPECT_LE(convex.proxyToOriginals - convex.proxyToOriginalsLower, tolerance * (1 + 1e-9));
    EXPECT_LT(2 * convex.evaluationCount, plain.evaluationCount);
}
