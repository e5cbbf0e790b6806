// SPDX-License-Identifier: AGPL-3.0-or-later
// Tests of the hierarchy nodes for real-time use (issue 4, deliverable 1; docs/design.md §2.5, 2.6):
// bounds nested, errors monotone, every original object under exactly one root path,
// proxies simpler than the exact aggregates, an independent denser error measurement below
// the stored error, collapsed unchanged aggregates, determinism over thread counts.
#include <aggrelod/aggregate3d.h>
#include <aggrelod/hierarchy_nodes.h>
#include <aggrelod/samples.h>

#include "mesh_distance.h"

#include <gtest/gtest.h>

#include "grid_measure.h"
#include "test_support.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <utility>
#include <set>

using namespace aggrelod;

namespace {

using aggrelod::testing::gridMeasure;

struct Baked {
    std::vector<InputObject> objects;
    Hierarchy3D hierarchy;
    HierarchyNodes nodes;
};

/// The 15-spheres scene at the paper's deltas, baked once for the whole file.
const Baked& spheres15() {
    static const Baked baked = [] {
        Baked b;
        b.objects = samples::makeSpheres15(1);
        Settings3D s;
        s.deltas = {1, 1.5, 2, 3, 4};
        s.threadCount = 2;
        EXPECT_TRUE(buildHierarchy3D(b.objects, s, b.hierarchy));
        ProxySettings p;
        p.threadCount = 2;
        std::string error;
        EXPECT_TRUE(buildHierarchyNodes(b.hierarchy, b.objects, p, b.nodes, error)) << error;
        return b;
    }();
    return baked;
}

bool boxInside(const HierarchyNode& inner, const HierarchyNode& outer) {
    for (int k = 0; k < 3; ++k)
        if (inner.boundsMin[k] < outer.boundsMin[k] || inner.boundsMax[k] > outer.boundsMax[k]) return false;
    return true;
}

/// Sphere nesting evaluated in float, as a runtime reading the file would.
bool sphereInsideFloat(const HierarchyNode& inner, const HierarchyNode& outer) {
    float d2 = 0;
    for (int k = 0; k < 3; ++k) {
        const float d = float(inner.sphereCenter[k]) - float(outer.sphereCenter[k]);
        d2 += d * d;
    }
    return std::sqrt(d2) + float(inner.sphereRadius) <= float(outer.sphereRadius);
}

/// Nodes and triangles of the cut the runtime's screen-space rule selects (docs/design.md §3):
/// from the roots down, a node is drawn when its geometric error seen from `eye` at the nearest
/// point of its bounding sphere is at most `pixels` (1080 px viewport, 60 degree field of view).
std::pair<size_t, size_t> cutNodesAndTriangles(const HierarchyNodes& h, const double eye[3], double pixels) {
    const double k = 1080.0 / (2 * std::tan(3.14159265358979323846 / 6));
    size_t drawn = 0, triangles = 0;
    std::vector<uint32_t> stack(h.roots.begin(), h.roots.end());
    while (!stack.empty()) {
        const HierarchyNode& n = h.nodes[stack.back()];
        stack.pop_back();
        double d2 = 0;
        for (int c = 0; c < 3; ++c) d2 += (eye[c] - n.sphereCenter[c]) * (eye[c] - n.sphereCenter[c]);
        const double d = std::max(std::sqrt(d2) - n.sphereRadius, 1e-9);
        if (n.leaf || n.geometricError * k / d <= pixels) {
            ++drawn;
            triangles += n.indices.size() / 3;
        } else {
            stack.insert(stack.end(), n.children.begin(), n.children.end());
        }
    }
    return {drawn, triangles};
}

/// The forest sample's hierarchy (8 automatic levels) with the default proxies and with the
/// proxies `change` makes different: the same hierarchy, so that the two trees differ only there.
struct ForestPair {
    std::vector<InputObject> objects = samples::makeForest(1);
    HierarchyNodes with, without;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    double diameter = 0;

    /// Cut figures summed over 8 cameras on a circle at `distance` scene diameters (as
    /// bench_lod_budget): {nodes, triangles} with and without.
    std::array<size_t, 4> cuts(int distance) const {
        std::array<size_t, 4> sum{};
        for (int az = 0; az < 8; ++az) {
            const double phi = 2 * 3.14159265358979323846 * az / 8, r = distance * diameter;
            const double eye[3] = {0.5 * (lo[0] + hi[0]) + r * std::cos(phi), 0.5 * (lo[1] + hi[1]) + r * std::sin(phi),
                                   0.5 * (lo[2] + hi[2]) + 0.4 * r};
            const auto [a, b] = cutNodesAndTriangles(with, eye, 1.0);
            const auto [c, d] = cutNodesAndTriangles(without, eye, 1.0);
            sum[0] += a, sum[1] += b, sum[2] += c, sum[3] += d;
        }
        return sum;
    }
};

bool bakeForestPair(ForestPair& f, void (*change)(ProxySettings&)) {
    Settings3D s;
    s.automaticLevelCount = 8;
    s.threadCount = 2;
    Hierarchy3D hierarchy;
    if (!buildHierarchy3D(f.objects, s, hierarchy)) return false;
    ProxySettings p;
    p.threadCount = 2;
    std::string error;
    if (!buildHierarchyNodes(hierarchy, f.objects, p, f.with, error)) return false;
    change(p);
    if (!buildHierarchyNodes(hierarchy, f.objects, p, f.without, error)) return false;
    for (const InputObject& o : f.objects)
        for (size_t v = 0; v < o.positions.size(); v += 3)
            for (int c = 0; c < 3; ++c)
                f.lo[c] = std::min(f.lo[c], o.positions[v + c]), f.hi[c] = std::max(f.hi[c], o.positions[v + c]);
    for (int c = 0; c < 3; ++c) f.diameter += (f.hi[c] - f.lo[c]) * (f.hi[c] - f.lo[c]);
    f.diameter = std::sqrt(f.diameter);
    return true;
}

}  // namespace

// Coarser versions of an aggregate (docs/design.md §2.6): each sits between an aggregate and its
// parent with the aggregate's objects, one child, fewer triangles, an error within its budget
// and below the parent's; and they make the drawn cut lighter at middle and far distances
// than the same hierarchy without them.
TEST(HierarchyNodes, CoarserVersionsLightenTheCut) {
    ForestPair f;
    ASSERT_TRUE(bakeForestPair(f, [](ProxySettings& p) { p.coarserCount = 0; }));
    const HierarchyNodes& with = f.with;

    size_t coarser = 0;
    for (size_t i = 0; i < with.nodes.size(); ++i) {
        const HierarchyNode& n = with.nodes[i];
        if (n.coarserStep == 0) continue;
        ++coarser;
        ASSERT_EQ(n.children.size(), 1u) << "node " << i;
        const HierarchyNode& below = with.nodes[n.children[0]];
        EXPECT_FALSE(below.leaf);
        EXPECT_EQ(below.objectLod, 0);
        EXPECT_EQ(below.coarserStep, n.coarserStep - 1) << "node " << i;
        EXPECT_EQ(n.sources, below.sources);
        EXPECT_EQ(n.firstLevel, -1);
        EXPECT_LE(10 * n.indices.size(), 9 * below.indices.size()) << "node " << i << " is not 10 % lighter";
        EXPECT_LE(n.error.bound(), n.budget) << "node " << i;
        // Below its parent's error (a bundle holding it may have the same error: its part's).
        if (n.parent != kNoNode && with.nodes[n.parent].coarserStep == 0 && with.nodes[n.parent].bundleStep == 0)
            EXPECT_LT(n.error.bound(), with.nodes[n.parent].error.bound()) << "node " << i;
    }
    for (const HierarchyNode& n : f.without.nodes) EXPECT_EQ(n.coarserStep, 0);
    std::printf("forest: %zu coarser versions over %zu nodes\n", coarser, with.nodes.size());
    EXPECT_GT(coarser, 20u);

    for (int distance : {4, 8, 16}) {  // cameras at 4, 8 and 16 scene diameters
        const auto [withNodes, withTriangles, withoutNodes, withoutTriangles] = f.cuts(distance);
        std::printf("  %2d diameters: cut %zu triangles with coarser versions, %zu without (8 cameras)\n", distance,
                    withTriangles, withoutTriangles);
        EXPECT_LT(withTriangles, withoutTriangles) << distance << " diameters";
    }
}

// Bundles (docs/design.md §2.6): below an aggregate of several objects, a chain of merged
// meshes of its children's versions, each with an error within its threshold and below the
// aggregate's, holding more of its children than the bundle below it or lighter; a child
// hangs below the finest bundle holding it, the others beside the chain; a distant cut draws
// at most a tenth of the nodes with them on the forest, at about the same triangles.
TEST(HierarchyNodes, BundlesDrawADistantGroupInOneCall) {
    ForestPair f;
    ASSERT_TRUE(bakeForestPair(f, [](ProxySettings& p) { p.bundleCount = 0; }));
    const HierarchyNodes& with = f.with;
    const std::vector<InputObject>& objects = f.objects;

    size_t bundles = 0, underBundles = 0, joining = 0;
    for (size_t i = 0; i < with.nodes.size(); ++i) {
        const HierarchyNode& n = with.nodes[i];
        if (n.bundleStep == 0) continue;
        ++bundles;
        ASSERT_NE(n.parent, kNoNode);
        const HierarchyNode& above = with.nodes[n.parent];
        const HierarchyNode& group = with.nodes[aggregateBelow(with, uint32_t(i))];
        EXPECT_EQ(group.bundleStep, 0);
        EXPECT_EQ(group.coarserStep, 0);
        EXPECT_GE(group.sources.size(), 2u);
        EXPECT_TRUE(std::includes(group.sources.begin(), group.sources.end(), n.sources.begin(), n.sources.end()));
        EXPECT_GE(n.sources.size(), 2u);
        EXPECT_EQ(n.firstLevel, -1);
        EXPECT_GE(n.bundleLevel, 0);
        EXPECT_LE(n.bundleLevel, group.firstLevel);  // its own group's, or a group below that gave way
        EXPECT_LE(n.error.bound(), n.budget) << "node " << i;
        EXPECT_LT(n.budget, group.error.bound()) << "node " << i;
        EXPECT_LE(n.geometricError, above.geometricError);
        if (above.bundleStep >= 1 && above.bundleLevel == n.bundleLevel) {  // the next coarser bundle of its group
            EXPECT_EQ(above.bundleStep, n.bundleStep + 1);
            EXPECT_TRUE(std::includes(above.sources.begin(), above.sources.end(), n.sources.begin(), n.sources.end()));
            if (above.sources == n.sources) {
                EXPECT_LE(10 * above.indices.size(), 9 * n.indices.size()) << "node " << n.parent << " is not 10 % lighter";
            } else {
                ++joining;  // holds more of the group's children
            }
            EXPECT_GT(above.budget, n.budget);
        } else if (above.bundleStep >= 1) {
            // The coarsest bundle left of a group that left the tree: a part of the bundle of
            // a group above that it joins, within its threshold.
            ++underBundles;
            EXPECT_LT(n.bundleLevel, above.bundleLevel) << "node " << i;
            EXPECT_TRUE(std::includes(above.sources.begin(), above.sources.end(), n.sources.begin(), n.sources.end()));
            EXPECT_LT(n.sources.size(), above.sources.size());
            EXPECT_LE(float(n.geometricError), std::nextafter(float(above.budget), INFINITY)) << "node " << i;
        } else {
            EXPECT_EQ(&above, &group);
            // The group's other children (aggregates with wide fills) beside the chain, apart.
            size_t beside = 0;
            for (uint32_t c : above.children) beside += with.nodes[c].bundleStep == 0;
            EXPECT_EQ(beside + 1, above.children.size());
        }
        // A bundle stands for exactly its children's objects (the finer bundle and the
        // children that join it), each within its threshold.
        std::vector<uint32_t> below;
        for (uint32_t c : n.children) {
            below.insert(below.end(), with.nodes[c].sources.begin(), with.nodes[c].sources.end());
            EXPECT_LE(float(with.nodes[c].geometricError), std::nextafter(float(n.budget), INFINITY)) << "node " << c;
        }
        std::sort(below.begin(), below.end());
        EXPECT_EQ(below, n.sources) << "node " << i;
        if (n.bundleStep == 1) {
            EXPECT_GE(n.children.size(), 2u);
            size_t childTriangles = 0;
            for (uint32_t c : n.children)
                childTriangles += with.nodes[c].leaf ? objects[c].indices.size() / 3 : with.nodes[c].indices.size() / 3;
            EXPECT_LE(n.indices.size() / 3, childTriangles) << "node " << i;
        }
    }
    for (const HierarchyNode& n : f.without.nodes) EXPECT_EQ(n.bundleStep, 0);
    std::printf("forest: %zu bundles over %zu nodes (%zu without), %zu of them under a group's bundles, %zu holding "
                "more children than the finer one\n",
                bundles, with.nodes.size(), f.without.nodes.size(), underBundles, joining);
    EXPECT_GT(bundles, 20u);
    EXPECT_GT(underBundles, 5u);  // groups whose children are all bundled are bundled with their siblings

    for (int distance : {8, 16}) {
        const auto [withNodes, withTriangles, withoutNodes, withoutTriangles] = f.cuts(distance);
        std::printf("  %2d diameters: cut of %zu nodes, %zu triangles with bundles; %zu nodes, %zu triangles without "
                    "(8 cameras)\n",
                    distance, withNodes, withTriangles, withoutNodes, withoutTriangles);
        EXPECT_LE(10 * withNodes, withoutNodes) << distance << " diameters";
        EXPECT_LE(withTriangles, withoutTriangles + withoutTriangles / 10) << distance << " diameters";
    }
}

// A child whose versions all have errors above a group's finest bundle (on the village: a
// row of houses whose aggregate has a wide fill) joins the group's first bundle whose
// threshold reaches it, so that the whole village is drawn in one call from 16 diameters on,
// where it would otherwise be drawn in ten.
TEST(HierarchyNodes, BundlesTakeInChildrenWithWideFillsAtTheirErrors) {
    ForestPair f;
    f.objects = samples::makeVillage(1);
    ASSERT_TRUE(bakeForestPair(f, [](ProxySettings& p) { p.bundleCount = 0; }));
    const HierarchyNodes& with = f.with;
    size_t joining = 0;
    for (const HierarchyNode& n : with.nodes) {
        if (n.bundleStep == 0 || n.parent == kNoNode) continue;
        const HierarchyNode& above = with.nodes[n.parent];
        if (above.bundleStep == 0 || above.bundleLevel != n.bundleLevel || above.sources == n.sources) continue;
        ++joining;  // above holds more of the group's children than n: they hang below it, within its threshold
        std::vector<uint32_t> below(n.sources);
        for (uint32_t c : above.children) {
            if (&with.nodes[c] == &n) continue;
            if (with.nodes[c].bundleStep >= 1) EXPECT_LT(with.nodes[c].bundleLevel, n.bundleLevel);  // a group below's
            EXPECT_GT(with.nodes[c].geometricError, n.budget);  // it could not join the finer bundle
            EXPECT_LE(float(with.nodes[c].geometricError), std::nextafter(float(above.budget), INFINITY));
            below.insert(below.end(), with.nodes[c].sources.begin(), with.nodes[c].sources.end());
        }
        std::sort(below.begin(), below.end());
        EXPECT_EQ(below, above.sources);
    }
    const auto [withNodes, withTriangles, withoutNodes, withoutTriangles] = f.cuts(16);
    std::printf("village: %zu bundles holding more children than the finer one; 16 diameters: cut of %zu nodes, %zu "
                "triangles with bundles; %zu nodes, %zu triangles without (8 cameras)\n",
                joining, withNodes, withTriangles, withoutNodes, withoutTriangles);
    EXPECT_GT(joining, 0u);
    EXPECT_LE(withNodes, 2u * 8);
    EXPECT_LE(withTriangles, withoutTriangles + withoutTriangles / 10);
}

// Bundles draw the objects' own versions where those are lighter than the group's (whose
// versions keep the fill between the objects): a group's coarsest bundle has at most 10/9 of
// the triangles of its objects' lightest enclosing versions within its error (10/9: the
// chains keep a version only when it is a tenth lighter than the one before), and on the
// forest it is strictly lighter than the same group's coarsest bundle made without them.
TEST(HierarchyNodes, BundlesDrawTheObjectsOwnVersionsWhereLighter) {
    ForestPair f;
    ASSERT_TRUE(bakeForestPair(f, [](ProxySettings&) {}));
    const HierarchyNodes& with = f.with;
    std::vector<std::vector<HierarchyNode>> versions(f.objects.size());
    for (size_t o = 0; o < f.objects.size(); ++o) versions[o] = enclosingVersions(f.objects[o], nullptr, ProxySettings{});

    size_t checked = 0, sumBundles = 0, sumVersions = 0;
    for (size_t i = 0; i < with.nodes.size(); ++i) {
        const HierarchyNode& n = with.nodes[i];
        if (n.bundleStep == 0 || with.nodes[n.parent].bundleStep != 0) continue;  // a group's coarsest bundle
        size_t lightest = 0;
        bool all = true;
        for (uint32_t o : n.sources) {
            size_t best = SIZE_MAX;
            for (const HierarchyNode& v : versions[o])
                if (v.error.bound() <= n.error.bound()) best = std::min(best, v.indices.size() / 3);
            all = all && best != SIZE_MAX;
            lightest += best == SIZE_MAX ? 0 : best;
        }
        if (!all) continue;
        ++checked;
        sumBundles += n.indices.size() / 3;
        sumVersions += lightest;
        EXPECT_LE(9 * (n.indices.size() / 3), 10 * lightest) << "bundle " << i << " of " << n.sources.size() << " objects";
    }
    std::printf("forest: %zu groups' coarsest bundles, %zu triangles; their objects' lightest versions within the "
                "bundles' errors: %zu\n",
                checked, sumBundles, sumVersions);
    EXPECT_GT(checked, 10u);
}

TEST(HierarchyNodes, TreeShapeBoundsAndErrors) {
    const Baked& b = spheres15();
    const auto& nodes = b.nodes.nodes;
    ASSERT_EQ(b.nodes.objectCount, b.objects.size());
    ASSERT_GT(nodes.size(), b.objects.size());
    size_t aggregates = 0;
    for (const Level& l : b.hierarchy.levels) aggregates += l.aggregates.size();
    size_t aggregateNodes = 0, objectLodNodes = 0;
    for (const HierarchyNode& n : nodes) {
        if (n.leaf) continue;
        if (n.coarserStep == 0 && n.bundleStep == 0) ++(n.objectLod > 0 ? objectLodNodes : aggregateNodes);
        if (n.objectLod > 0) {  // per-object LOD: one object, no level, within its budget
            EXPECT_EQ(n.sources.size(), 1u);
            EXPECT_EQ(n.firstLevel, -1);
            EXPECT_EQ(n.children.size(), 1u);
        }
        EXPECT_LE(n.error.bound(), n.budget);
    }
    std::printf("spheres15: %zu objects, %zu aggregates over %zu levels -> %zu aggregate nodes, %zu per-object LOD "
                "nodes, %zu roots\n",
                b.objects.size(), aggregates, b.hierarchy.levels.size(), aggregateNodes, objectLodNodes,
                b.nodes.roots.size());
    EXPECT_GT(objectLodNodes, 0u);
    // Unchanged aggregates are collapsed: fewer nodes than aggregates, and each aggregate maps
    // to a node spanning its level with the same objects.
    EXPECT_LT(aggregateNodes, aggregates);
    for (size_t k = 0; k < b.hierarchy.levels.size(); ++k)
        for (size_t g = 0; g < b.hierarchy.levels[k].aggregates.size(); ++g) {
            const HierarchyNode& n = nodes[b.nodes.nodeOfAggregate[k][g]];
            EXPECT_EQ(n.sources, b.hierarchy.levels[k].aggregates[g].sourceObjects);
            if (n.objectLod > 0) continue;  // an object alone, stood in for by its per-object LOD chain
            if (n.bundleStep > 0) {  // a group that gave way to the bundles above: its bundle stands for it
                EXPECT_LE(n.bundleLevel, int(k));
                continue;
            }
            EXPECT_LE(n.firstLevel, int(k));
            EXPECT_GE(n.lastLevel, int(k));
        }

    for (size_t i = 0; i < nodes.size(); ++i) {
        const HierarchyNode& n = nodes[i];
        EXPECT_EQ(n.leaf, i < b.objects.size());
        if (n.leaf) {
            EXPECT_EQ(n.geometricError, 0.0);
            EXPECT_TRUE(n.children.empty());
        } else {
            // Children partition the node's objects.
            std::vector<uint32_t> fromChildren;
            for (uint32_t c : n.children) fromChildren.insert(fromChildren.end(), nodes[c].sources.begin(), nodes[c].sources.end());
            std::sort(fromChildren.begin(), fromChildren.end());
            EXPECT_EQ(fromChildren, n.sources) << "node " << i;
            EXPECT_GE(n.geometricError, n.error.bound()) << "node " << i;
            EXPECT_EQ(double(float(n.geometricError)), n.geometricError);
        }
        for (uint32_t c : n.children) {
            EXPECT_LT(c, i);
            EXPECT_EQ(nodes[c].parent, i);
            EXPECT_GE(n.geometricError, nodes[c].geometricError) << "error not monotone at node " << i;
            EXPECT_TRUE(boxInside(nodes[c], n)) << "box of node " << c << " not inside its parent " << i;
            EXPECT_TRUE(sphereInsideFloat(nodes[c], n)) << "sphere of node " << c << " not inside its parent " << i;
        }
        // The node's own proxy lies in its box.
        for (size_t v = 0; v < n.positions.size(); v += 3)
            for (int k = 0; k < 3; ++k) {
                EXPECT_GE(n.positions[v + k], n.boundsMin[k]);
                EXPECT_LE(n.positions[v + k], n.boundsMax[k]);
            }
    }
    // Every original object lies under exactly one root, on one path of parents.
    std::vector<int> rootHits(b.objects.size(), 0);
    for (uint32_t r : b.nodes.roots) {
        EXPECT_EQ(nodes[r].parent, kNoNode);
        for (uint32_t o : nodes[r].sources) ++rootHits[o];
    }
    for (size_t o = 0; o < b.objects.size(); ++o) {
        EXPECT_EQ(rootHits[o], 1) << b.objects[o].name;
        size_t steps = 0;
        for (uint32_t n = uint32_t(o); nodes[n].parent != kNoNode; n = nodes[n].parent) {
            ASSERT_LT(++steps, nodes.size()) << "cycle above object " << o;
            EXPECT_TRUE(std::binary_search(nodes[nodes[n].parent].sources.begin(), nodes[nodes[n].parent].sources.end(), uint32_t(o)));
        }
    }
}

TEST(HierarchyNodes, ProxiesAreSimplerAndTheirStoredErrorBoundsAnIndependentMeasurement) {
    const Baked& b = spheres15();
    const auto& nodes = b.nodes.nodes;
    size_t exact = 0, proxy = 0, reduced = 0;
    double worstRatio = 0, found = 1;
    for (size_t i = b.objects.size(); i < nodes.size(); ++i) {
        const HierarchyNode& n = nodes[i];
        exact += n.exactTriangleCount;
        proxy += n.indices.size() / 3;
        EXPECT_LE(n.indices.size() / 3, n.exactTriangleCount);
        EXPECT_GT(n.indices.size(), 0u);
        reduced += n.indices.size() / 3 < n.exactTriangleCount;
        // An independent measurement: a 15-point barycentric grid on every triangle of both
        // meshes, exact closest points, inside-ness by the winding number. Its maximum never
        // exceeds the certified bound stored in the node.
        std::vector<const InputObject*> originals;
        for (uint32_t o : n.sources) originals.push_back(&b.objects[o]);
        const double measured = gridMeasure(n.positions, n.indices, originals, 4).worst();
        EXPECT_LE(measured, n.geometricError) << "node " << i;
        EXPECT_LE(measured, n.error.bound()) << "node " << i;
        worstRatio = std::max(worstRatio, measured / n.geometricError);
        found = std::min(found, std::max(n.error.proxyToOriginalsLower, n.error.originalsToProxyLower) / n.error.bound());
        EXPECT_GT(n.error.proxyToOriginals, 0.0) << "an aggregate adds fill: its proxy is away from the originals somewhere";
    }
    std::printf("spheres15 proxies: %zu -> %zu triangles (%.0f%%), %zu of %zu simplified; "
                "grid measurement / stored error <= %.2f; found / certified bound >= %.2f\n",
                exact, proxy, 100.0 * double(proxy) / double(exact), reduced, nodes.size() - b.objects.size(), worstRatio,
                found);
    EXPECT_LT(proxy, exact * 3 / 4);
    EXPECT_GT(reduced, 0u);
}

TEST(HierarchyNodes, SameNodesForOneAndTwoThreads) {
    const Baked& b = spheres15();
    ProxySettings p;
    p.threadCount = 1;
    HierarchyNodes single;
    std::string error;
    ASSERT_TRUE(buildHierarchyNodes(b.hierarchy, b.objects, p, single, error)) << error;
    ASSERT_EQ(single.nodes.size(), b.nodes.nodes.size());
    for (size_t i = 0; i < single.nodes.size(); ++i) {
        const HierarchyNode &x = single.nodes[i], &y = b.nodes.nodes[i];
        EXPECT_EQ(x.positions, y.positions);
        EXPECT_EQ(x.indices, y.indices);
        EXPECT_EQ(x.geometricError, y.geometricError);
        EXPECT_EQ(x.sphereRadius, y.sphereRadius);
        EXPECT_EQ(x.children, y.children);
    }
}

TEST(HierarchyNodes, MismatchedObjectsAreRefusedWithAMessage) {
    const Baked& b = spheres15();
    std::vector<InputObject> fewer(b.objects.begin(), b.objects.end() - 1);
    HierarchyNodes out;
    std::string error;
    EXPECT_FALSE(buildHierarchyNodes(b.hierarchy, fewer, ProxySettings{}, out, error));
    EXPECT_NE(error.find("refers to object 14"), std::string::npos) << error;
}

TEST(HierarchyNodes, ProxyErrorOfKnownShapes) {
    // A unit cube as its own proxy: 0 both ways. A proxy shrunk by 10 % around the centre:
    // proxy -> originals = originals -> proxy = the largest corner displacement, sqrt(3) * 0.05.
    const InputObject cube = samples::makeBox("cube", {0, 0, 0}, {1, 1, 1});
    const std::vector<float> same(cube.positions.begin(), cube.positions.end());
    const ProxyError exact = measureProxyError(same, cube.indices, {&cube}, 1e-3, 20000);
    EXPECT_LE(exact.bound(), 1e-3);
    std::vector<float> shrunk;
    for (double x : cube.positions) shrunk.push_back(float(0.5 + 0.9 * (x - 0.5)));
    const ProxyError inner = measureProxyError(shrunk, cube.indices, {&cube}, 1e-4, 200000);
    const double corner = std::sqrt(3.0) * 0.05;
    EXPECT_NEAR(inner.proxyToOriginals, 0.05, 1e-3);   // a face centre of the shrunk cube
    EXPECT_NEAR(inner.originalsToProxy, corner, 1e-3);  // an original corner
    EXPECT_GE(inner.originalsToProxy, inner.originalsToProxyLower);
    EXPECT_LE(inner.originalsToProxy - inner.originalsToProxyLower, 1e-4 + 1e-7);
    // A proxy grown by 10 %: the originals are inside it (distance to the solid 0).
    std::vector<float> grown;
    for (double x : cube.positions) grown.push_back(float(0.5 + 1.1 * (x - 0.5)));
    const ProxyError outer = measureProxyError(grown, cube.indices, {&cube}, 1e-4, 200000);
    EXPECT_NEAR(outer.proxyToOriginals, corner, 1e-3);
    EXPECT_LE(outer.originalsToProxy, 1e-4);
    // Nothing drawn: the error is the originals' extent.
    const ProxyError none = measureProxyError({}, {}, {&cube}, 1e-3, 100);
    EXPECT_NEAR(none.bound(), std::sqrt(3.0), 1e-12);
}

TEST(HierarchyNodes, EnclosingVersionsOfAnObjectContainItWithinTheirCertifiedError) {
    // The versions a conservative per-object LOD is chosen from: ascending error, each closed,
    // containing every vertex of the object, its certified error covering a dense grid
    // measurement and within its budget; the coarsest is far lighter than the object.
    const InputObject vase = samples::makeLathe("vase", {0, 0, 0}, {{0.5, 0}, {0.3, 0.4}, {0.45, 0.8}, {0.2, 1.2}}, 24);
    const std::vector<HierarchyNode> versions = enclosingVersions(vase, nullptr, ProxySettings{});
    ASSERT_GE(versions.size(), 3u);
    for (size_t i = 0; i < versions.size(); ++i) {
        const HierarchyNode& v = versions[i];
        if (i > 0) EXPECT_GE(v.error.bound(), versions[i - 1].error.bound());
        EXPECT_LE(v.error.bound(), v.budget);
        const std::vector<double> p(v.positions.begin(), v.positions.end());
        detail::TriangleBvh surface;
        surface.build(p.data(), p.size() / 3, v.indices.data(), v.indices.size() / 3);
        for (size_t k = 0; k + 2 < vase.positions.size(); k += 3) {
            const bool on = detail::closestPoint(surface, &vase.positions[k]).distance <= 1e-6;
            EXPECT_TRUE(on || aggrelod::testing::windingNumber(p, v.indices, &vase.positions[k]) > 0.5)
                << "version " << i << ", vertex " << k / 3;
        }
        const aggrelod::testing::GridMeasured m = aggrelod::testing::gridMeasure(v.positions, v.indices, {&vase}, 6);
        EXPECT_GE(v.error.bound() + 1e-9, m.proxyToOriginals) << "version " << i;
    }
    EXPECT_LT(versions.back().indices.size() * 4, vase.indices.size());
    // An open object without a solid standing in for it has none.
    InputObject open = vase;
    open.indices.resize(open.indices.size() - 3);
    EXPECT_TRUE(enclosingVersions(open, nullptr, ProxySettings{}).empty());
}

TEST(HierarchyNodes, AnOpenSupportSurfaceGetsVersionsThatContainIt) {
    // An open, rolling ground (a support surface: the bake made no solid for it) is simplified
    // from a thin solid made around it: every version closed and outward, containing every
    // vertex of the surface, within its budget and covering a dense grid measurement.
    InputObject ground;
    ground.name = "ground";
    const int n = 24;
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i) {
            const double x = i * 100.0 / n, y = j * 100.0 / n;
            ground.positions.insert(ground.positions.end(), {x, y, 3 * std::sin(x / 15) * std::cos(y / 20)});
        }
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const uint32_t a = uint32_t(j * (n + 1) + i), b = a + 1, c = a + uint32_t(n + 1), d = c + 1;
            ground.indices.insert(ground.indices.end(), {a, b, d, a, d, c});
        }
    EXPECT_TRUE(enclosingVersions(ground, nullptr, ProxySettings{}).empty()) << "not a support surface: no solid";
    const std::vector<HierarchyNode> versions = enclosingVersions(ground, nullptr, ProxySettings{}, true);
    ASSERT_GE(versions.size(), 2u);
    for (size_t i = 0; i < versions.size(); ++i) {
        const HierarchyNode& v = versions[i];
        EXPECT_LE(v.error.bound(), v.budget) << "version " << i;
        InputObject mesh;
        mesh.positions.assign(v.positions.begin(), v.positions.end());
        mesh.indices = v.indices;
        EXPECT_EQ(aggrelod::testing::checkClosedAfterWeld(mesh).problem, "") << "version " << i;
        EXPECT_GT(aggrelod::testing::signedVolumeOf(mesh), 0.0) << "version " << i;
        detail::TriangleBvh surface;
        surface.build(mesh.positions.data(), mesh.positions.size() / 3, v.indices.data(), v.indices.size() / 3);
        for (size_t k = 0; k + 2 < ground.positions.size(); k += 3) {
            const bool on = detail::closestPoint(surface, &ground.positions[k]).distance <= 1e-6;
            EXPECT_TRUE(on || aggrelod::testing::windingNumber(mesh.positions, v.indices, &ground.positions[k]) > 0.5)
                << "version " << i << ", vertex " << k / 3;
        }
        const aggrelod::testing::GridMeasured m = aggrelod::testing::gridMeasure(v.positions, v.indices, {&ground}, 6);
        EXPECT_GE(v.error.bound() + 1e-9, m.proxyToOriginals) << "version " << i;
    }
    EXPECT_LT(versions.back().indices.size() * 4, ground.indices.size());
}
