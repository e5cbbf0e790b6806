// SPDX-License-Identifier: AGPL-3.0-or-later
// Collision shapes per hierarchy node: a convex hull per shell, kept when its certified
// distance to the originals fits the node's error (collision_shapes.h).
#include <aggrelod/collision_shapes.h>
#include <aggrelod/disjoint_sets.h>

#include "convex_hull.h"
#include "parallel_for.h"
#include "proxy_error.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <stdexcept>

namespace aggrelod {
namespace {

/// Shells of a triangle mesh: triangles joined through vertices of equal position. Returns,
/// per shell in order of its first triangle, the distinct positions of its vertices (doubles,
/// sorted, so the hull input does not depend on the triangle order).
std::vector<std::vector<double>> shellPoints(const std::vector<float>& positions, const std::vector<uint32_t>& indices) {
    const size_t vertexCount = positions.size() / 3;
    // Weld: vertices with bit-identical positions get the smallest such index.
    std::vector<uint32_t> order(vertexCount);
    std::iota(order.begin(), order.end(), 0u);
    auto key = [&](uint32_t v) {
        return std::array<float, 3>{positions[3 * size_t(v)], positions[3 * size_t(v) + 1], positions[3 * size_t(v) + 2]};
    };
    std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
        const auto ka = key(a), kb = key(b);
        return ka != kb ? ka < kb : a < b;
    });
    std::vector<uint32_t> weld(vertexCount);
    for (size_t i = 0; i < order.size();) {
        size_t j = i;
        while (j < order.size() && key(order[j]) == key(order[i])) ++j;
        for (size_t k = i; k < j; ++k) weld[order[k]] = order[i];
        i = j;
    }
    DisjointSets sets(vertexCount);
    for (size_t t = 0; t + 2 < indices.size(); t += 3)
        for (int k = 1; k < 3; ++k) sets.unite(weld[indices[t]], weld[indices[t + k]]);
    std::vector<uint32_t> shellOf(vertexCount, ~0u);
    std::vector<std::vector<uint32_t>> members;
    for (size_t t = 0; t + 2 < indices.size(); t += 3)
        for (int k = 0; k < 3; ++k) {
            const uint32_t v = weld[indices[t + k]], root = sets.find(v);
            if (shellOf[root] == ~0u) {
                shellOf[root] = uint32_t(members.size());
                members.emplace_back();
            }
            members[shellOf[root]].push_back(v);
        }
    std::vector<std::vector<double>> out(members.size());
    for (size_t s = 0; s < members.size(); ++s) {
        std::vector<uint32_t>& m = members[s];
        std::sort(m.begin(), m.end(), [&](uint32_t a, uint32_t b) { return key(a) < key(b); });
        m.erase(std::unique(m.begin(), m.end()), m.end());
        for (uint32_t v : m)
            for (int k = 0; k < 3; ++k) out[s].push_back(double(positions[3 * size_t(v) + k]));
    }
    return out;
}

std::string formatLength(double x) {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%.6g", x);
    return buffer;
}

}  // namespace

bool buildCollisionShapes(const HierarchyNodes& nodes, const std::vector<InputObject>& objects,
                          const CollisionShapeSettings& settings, std::vector<NodeCollisionShapes>& out,
                          std::string& error) {
    out.clear();
    if (nodes.objectCount != objects.size() || nodes.nodes.size() < objects.size()) {
        error = "the hierarchy nodes do not belong to these objects";
        return false;
    }
    for (size_t i = 0; i < nodes.nodes.size(); ++i) {
        const HierarchyNode& n = nodes.nodes[i];
        if (n.positions.size() % 3 != 0 || n.indices.size() % 3 != 0) {
            error = "node " + std::to_string(i) + ": positions or indices size is not a multiple of 3";
            return false;
        }
        for (uint32_t v : n.indices)
            if (v >= n.positions.size() / 3) {
                error = "node " + std::to_string(i) + ": a triangle index is out of range";
                return false;
            }
        for (uint32_t s : n.sources)
            if (s >= objects.size()) {
                error = "node " + std::to_string(i) + " refers to object " + std::to_string(s);
                return false;
            }
    }
    try {
        // Each original object with geometry is prepared once for all the nodes holding it.
        std::vector<detail::PreparedOriginal> prepared(objects.size());
        std::vector<char> usable(objects.size(), 0);
        detail::parallelFor(objects.size(), settings.threadCount, [&](size_t o) {
            const InputObject& object = objects[o];
            if (object.indices.empty()) return;
            for (double c : object.positions)
                if (!std::isfinite(c)) return;
            detail::prepareOriginal(object, prepared[o]);
            usable[o] = 1;
        });

        out.assign(nodes.nodes.size(), NodeCollisionShapes{});
        detail::parallelFor(nodes.nodes.size(), settings.threadCount, [&](size_t i) {
            const HierarchyNode& n = nodes.nodes[i];
            NodeCollisionShapes& shapes = out[i];
            double diagonal = 0;
            for (int k = 0; k < 3; ++k) diagonal += (n.boundsMax[k] - n.boundsMin[k]) * (n.boundsMax[k] - n.boundsMin[k]);
            diagonal = std::sqrt(diagonal);
            shapes.allowance = n.geometricError + settings.roundingFraction * diagonal;
            if (nodeTriangleCount(n) == 0) {
                shapes.reason = "no geometry";
                return;
            }
            std::vector<const detail::PreparedOriginal*> originals;
            for (uint32_t s : n.sources)
                if (usable[s]) originals.push_back(&prepared[s]);
            NodeMesh storage;  // a leaf that refers to its object, or a spilled mesh, comes back here
            const NodeMeshView mesh = viewNodeMesh(nodes, objects, uint32_t(i), storage);
            const std::vector<std::vector<double>> shells = shellPoints(mesh.positions, mesh.indices);
            shapes.shellCount = shells.size();
            if (originals.empty()) {
                shapes.reason = "no original geometry to measure against";
                return;
            }
            if (shells.size() > settings.maxShells) {
                shapes.reason = std::to_string(shells.size()) + " shells (more than " + std::to_string(settings.maxShells) + ")";
                return;
            }
            // The measurement refines until its bound is within this of the largest distance
            // found, so a hull whose true distance is below allowance - tolerance passes.
            const double tolerance = 0.05 * shapes.allowance;
            detail::ProxyMeasureOptions options;
            options.enclosesOriginals = true;  // shell inside its hull, originals inside the shell's solid
            options.giveUpAbove = shapes.allowance;
            std::vector<ConvexPart> parts;
            double worst = 0;
            for (size_t s = 0; s < shells.size(); ++s) {
                std::vector<double> hullPositions;
                std::vector<uint32_t> hullTriangles;
                if (!detail::convexHull3(shells[s], hullPositions, hullTriangles)) {
                    shapes.reason = "shell " + std::to_string(s) + " is flat (no convex hull with volume)";
                    return;
                }
                if (settings.maxHullVertices > 0 && hullPositions.size() / 3 > settings.maxHullVertices) {
                    shapes.reason = "the hull of shell " + std::to_string(s) + " has " +
                                    std::to_string(hullPositions.size() / 3) + " vertices (more than " +
                                    std::to_string(settings.maxHullVertices) + ")";
                    return;
                }
                ConvexPart part;
                part.positions.assign(hullPositions.begin(), hullPositions.end());  // exact: mesh vertices
                part.indices = std::move(hullTriangles);
                const ProxyError e = detail::measureProxyErrorPrepared(part.positions, part.indices, originals, tolerance,
                                                                       settings.maxRefinementsPerDirection, options);
                part.errorBound = e.proxyToOriginals;
                if (!(part.errorBound <= shapes.allowance)) {
                    shapes.reason = "the hull of shell " + std::to_string(s) + " is up to " +
                                    formatLength(e.proxyToOriginalsLower) + " from the originals (certified bound " +
                                    formatLength(part.errorBound) + "), above the node's error " +
                                    formatLength(n.geometricError);
                    return;
                }
                worst = std::max(worst, part.errorBound);
                parts.push_back(std::move(part));
            }
            shapes.convexParts = std::move(parts);
            shapes.convexError = worst;
        });
    } catch (const std::exception& e) {
        out.clear();
        error = std::string("collision shapes: ") + e.what();
        return false;
    }
    return true;
}

}  // namespace aggrelod
