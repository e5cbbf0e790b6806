// SPDX-License-Identifier: AGPL-3.0-or-later
// Collision shapes per hierarchy node (collision_shapes.h): a convex hull per shell, kept only
// when its certified distance to the originals fits the node's error; the hulls contain the
// originals; an independent sampled distance never exceeds the certified bound.
#include <aggrelod/aggregate3d.h>
#include <aggrelod/collision_shapes.h>
#include <aggrelod/hierarchy_nodes.h>
#include <aggrelod/samples.h>

#include "mesh_distance.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <set>

using namespace aggrelod;

namespace {

/// Largest distance from points sampled on the triangles of `part` (a 6 x 6 barycentric grid
/// per triangle) to the nearest triangle of `objects`, brute force.
double sampledDistance(const ConvexPart& part, const std::vector<const InputObject*>& objects) {
    double worst = 0;
    for (size_t t = 0; t + 2 < part.indices.size(); t += 3)
        for (int i = 0; i <= 6; ++i)
            for (int j = 0; i + j <= 6; ++j) {
                double p[3];
                for (int k = 0; k < 3; ++k)
                    p[k] = (i * double(part.positions[3 * size_t(part.indices[t]) + k]) +
                            j * double(part.positions[3 * size_t(part.indices[t + 1]) + k]) +
                            (6 - i - j) * double(part.positions[3 * size_t(part.indices[t + 2]) + k])) / 6.0;
                double best = INFINITY, closest[3];
                for (const InputObject* o : objects)
                    for (size_t u = 0; u + 2 < o->indices.size(); u += 3)
                        best = std::min(best, detail::pointTriangleDistance(p, &o->positions[3 * size_t(o->indices[u])],
                                                                            &o->positions[3 * size_t(o->indices[u + 1])],
                                                                            &o->positions[3 * size_t(o->indices[u + 2])], closest));
                worst = std::max(worst, best);
            }
    return worst;
}

/// Whether every vertex of `object` lies inside the convex part (its triangles' planes),
/// within `slack`.
bool containsAll(const ConvexPart& part, const InputObject& object, double slack) {
    for (size_t t = 0; t + 2 < part.indices.size(); t += 3) {
        double a[3], u[3], v[3];
        for (int k = 0; k < 3; ++k) {
            a[k] = part.positions[3 * size_t(part.indices[t]) + k];
            u[k] = part.positions[3 * size_t(part.indices[t + 1]) + k] - a[k];
            v[k] = part.positions[3 * size_t(part.indices[t + 2]) + k] - a[k];
        }
        double n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
        const double l = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        if (!(l > 0)) continue;
        for (size_t i = 0; i + 2 < object.positions.size(); i += 3) {
            double d = 0;
            for (int k = 0; k < 3; ++k) d += n[k] / l * (object.positions[i + k] - a[k]);
            if (d > slack) return false;
        }
    }
    return true;
}

TEST(CollisionShapes, HullsOnlyWithinTheNodesErrorAndContainingTheOriginals) {
    // A convex box, a concave L-shaped prism and a sphere, far enough apart that the first
    // levels keep them alone, close enough that the last joins them.
    std::vector<InputObject> objects;
    objects.push_back(samples::makeBox("box", {0, 0, 0}, {1, 1, 1}));
    objects.push_back(samples::makeExtrusion("ell", {{0, 0}, {2, 0}, {2, 0.4}, {0.4, 0.4}, {0.4, 2}, {0, 2}}, 1, 0, {2.5, 0.5, 0}));
    objects.push_back(samples::makeUvSphere("ball", {6, 0.5, 0.5}, 0.5, 16, 8));
    for (uint32_t i = 0; i < objects.size(); ++i) objects[i].id = i;
    Settings3D settings;
    settings.deltas = {0.2, 3};
    settings.threadCount = 2;
    Hierarchy3D hierarchy;
    ASSERT_TRUE(buildHierarchy3D(objects, settings, hierarchy));
    HierarchyNodes nodes;
    ProxySettings proxies;
    proxies.threadCount = 2;
    std::string error;
    ASSERT_TRUE(buildHierarchyNodes(hierarchy, objects, proxies, nodes, error)) << error;
    CollisionShapeSettings cs;
    cs.threadCount = 2;
    std::vector<NodeCollisionShapes> shapes;
    ASSERT_TRUE(buildCollisionShapes(nodes, objects, cs, shapes, error)) << error;
    ASSERT_EQ(shapes.size(), nodes.nodes.size());

    // The leaves: the box and the sphere are convex (error 0 plus rounding), the L is not.
    ASSERT_EQ(shapes[0].convexParts.size(), 1u) << shapes[0].reason;
    EXPECT_LE(shapes[0].convexError, shapes[0].allowance);
    ASSERT_EQ(shapes[2].convexParts.size(), 1u) << shapes[2].reason;
    EXPECT_TRUE(shapes[1].convexParts.empty());
    EXPECT_NE(shapes[1].reason.find("above the node's error"), std::string::npos) << shapes[1].reason;

    size_t withParts = 0;
    for (size_t i = 0; i < nodes.nodes.size(); ++i) {
        const HierarchyNode& n = nodes.nodes[i];
        const NodeCollisionShapes& s = shapes[i];
        EXPECT_EQ(s.convexParts.empty(), !s.reason.empty()) << "node " << i;
        if (!n.indices.empty()) {
            EXPECT_GE(s.shellCount, 1u) << "node " << i;
        }
        if (s.convexParts.empty()) continue;
        ++withParts;
        EXPECT_DOUBLE_EQ(s.allowance, n.geometricError + cs.roundingFraction * std::sqrt(
                                                             (n.boundsMax[0] - n.boundsMin[0]) * (n.boundsMax[0] - n.boundsMin[0]) +
                                                             (n.boundsMax[1] - n.boundsMin[1]) * (n.boundsMax[1] - n.boundsMin[1]) +
                                                             (n.boundsMax[2] - n.boundsMin[2]) * (n.boundsMax[2] - n.boundsMin[2])));
        EXPECT_EQ(s.convexParts.size(), s.shellCount) << "node " << i;
        std::vector<const InputObject*> originals;
        for (uint32_t o : n.sources) originals.push_back(&objects[o]);
        // Hull vertices are vertices of the node's mesh, bit for bit.
        std::set<std::array<float, 3>> meshVertices;
        for (size_t v = 0; v + 2 < n.positions.size(); v += 3) meshVertices.insert({n.positions[v], n.positions[v + 1], n.positions[v + 2]});
        double largest = 0;
        for (const ConvexPart& part : s.convexParts) {
            for (size_t v = 0; v + 2 < part.positions.size(); v += 3)
                EXPECT_TRUE(meshVertices.count({part.positions[v], part.positions[v + 1], part.positions[v + 2]})) << "node " << i;
            EXPECT_LE(part.errorBound, s.allowance) << "node " << i;
            largest = std::max(largest, part.errorBound);
            // Independent check of the certified bound (sampled distances can only be lower).
            EXPECT_LE(sampledDistance(part, originals), part.errorBound + 1e-9) << "node " << i;
        }
        EXPECT_DOUBLE_EQ(s.convexError, largest);
        // The parts contain the originals: every original vertex inside some part.
        for (const InputObject* o : originals) {
            bool inside = false;
            for (const ConvexPart& part : s.convexParts) inside = inside || containsAll(part, *o, 1e-6);
            EXPECT_TRUE(inside) << "node " << i << ": " << o->name << " is not inside one hull";
        }
    }
    EXPECT_GE(withParts, 3u);

    // Deterministic over thread counts.
    cs.threadCount = 1;
    std::vector<NodeCollisionShapes> again;
    ASSERT_TRUE(buildCollisionShapes(nodes, objects, cs, again, error)) << error;
    for (size_t i = 0; i < shapes.size(); ++i) {
        ASSERT_EQ(again[i].convexParts.size(), shapes[i].convexParts.size());
        for (size_t j = 0; j < shapes[i].convexParts.size(); ++j) {
            EXPECT_EQ(again[i].convexParts[j].positions, shapes[i].convexParts[j].positions);
            EXPECT_EQ(again[i].convexParts[j].indices, shapes[i].convexParts[j].indices);
        }
    }
    // Objects that do not belong to the nodes are refused with a message.
    std::vector<InputObject> fewer(objects.begin(), objects.end() - 1);
    EXPECT_FALSE(buildCollisionShapes(nodes, fewer, cs, again, error));
    EXPECT_FALSE(error.empty());
}

}  // namespace
