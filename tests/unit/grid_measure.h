// SPDX-License-Identifier: AGPL-3.0-or-later
// Brute-force measurement of a proxy's distances to its originals, independent of the
// branch-and-bound in module/src/proxy_error.cpp: points on a barycentric grid of every
// triangle, exact closest points (BVH), inside-ness by the winding number. Shared by the
// proxy-error tests, which check that the certified bounds are never below it.
#pragma once

#include <aggrelod/aggregate3d.h>

#include "mesh_distance.h"
#include "test_support.h"

#include <algorithm>
#include <cstdint>
#include <vector>

namespace aggrelod::testing {

/// visit(point) on a barycentric grid of step 1/n on every triangle (xyz triples, corners).
template <class Visit>
void forEachGridPoint(const std::vector<double>& pos, const std::vector<uint32_t>& idx, int n, Visit&& visit) {
    for (size_t t = 0; t < idx.size(); t += 3)
        for (int i = 0; i <= n; ++i)
            for (int j = 0; i + j <= n; ++j) {
                double p[3];
                for (int k = 0; k < 3; ++k) {
                    const double a = pos[3 * idx[t] + k], b = pos[3 * idx[t + 1] + k], c = pos[3 * idx[t + 2] + k];
                    p[k] = a + (b - a) * i / n + (c - a) * j / n;
                }
                visit(p);
            }
}

/// Largest distances found on the grid, in scene units.
struct GridMeasured {
    double proxyToOriginals = 0;  ///< proxy points to the originals' surfaces
    double originalsToProxy = 0;  ///< original points outside the proxy solid to its surface
    double worst() const { return std::max(proxyToOriginals, originalsToProxy); }
};

/// Brute-force one-sided distances between a proxy (float xyz triples, triangle corners) and
/// its originals on a grid of step 1/n.
inline GridMeasured gridMeasure(const std::vector<float>& proxyPositions, const std::vector<uint32_t>& proxyIndices,
                                const std::vector<const InputObject*>& originals, int n) {
    std::vector<double> op, pp(proxyPositions.begin(), proxyPositions.end());
    std::vector<uint32_t> oi;
    for (const InputObject* o : originals) {
        const uint32_t base = uint32_t(op.size() / 3);
        op.insert(op.end(), o->positions.begin(), o->positions.end());
        for (uint32_t i : o->indices) oi.push_back(base + i);
    }
    detail::TriangleBvh origBvh, proxyBvh;
    origBvh.build(op.data(), op.size() / 3, oi.data(), oi.size() / 3);
    proxyBvh.build(pp.data(), pp.size() / 3, proxyIndices.data(), proxyIndices.size() / 3);
    GridMeasured m;
    forEachGridPoint(pp, proxyIndices, n, [&](const double* p) {
        m.proxyToOriginals = std::max(m.proxyToOriginals, detail::closestPoint(origBvh, p).distance);
    });
    forEachGridPoint(op, oi, n, [&](const double* p) {
        const double d = detail::closestPoint(proxyBvh, p).distance;
        if (d > m.originalsToProxy && windingNumber(pp, proxyIndices, p) < 0.5) m.originalsToProxy = d;
    });
    return m;
}

}  // namespace aggrelod::testing
