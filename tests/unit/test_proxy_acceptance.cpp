// SPDX-License-Identifier: AGPL-3.0-or-later
// Acceptance of the proxies an engine draws and collides against (docs/design.md §2.6), for every
// non-leaf node (aggregates and per-object LOD nodes) of in-process bakes of spheres15, chess,
// forest, village, truck_town without its ground and a 400-object generated scene:
//  - closed (after welding equal positions), edge-manifold (every index edge used by exactly
//    two triangles, once each way: a proxy whose vertices are ever split for attributes must
//    be welded before this check), positive volume;
//  - one shell per connected part: as many edge-connected shells as the exact aggregate's
//    componentCount (per-object LOD node: as its object);
//  - every original vertex of the node's sources inside or on the proxy;
//  - rays from outside reach the proxy no later than the originals (Embree);
//  - certified error within the node's budget, and an independent brute-force measurement on
//    a subset of nodes never above the certified bound.
// The checker itself is tested on the exact aggregates (which must pass the geometric checks)
// and on damaged copies of them (which must fail them), so a passing scene is not a checker
// that cannot fail.
#include "acceptance_scenes.h"
#include "grid_measure.h"
#include "mesh_distance.h"
#include "mesh_preparation.h"
#include "ray_scene.h"
#include "test_support.h"

#include <aggrelod/hierarchy_nodes.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <map>
#include <memory>
#include <numeric>
#include <random>
#include <sstream>
#include <string>
#include <vector>

using namespace aggrelod;
using namespace aggrelod::testing;

namespace {

// ------------------------------------------------------------------------------------------
// Baked scenes, once per test process.

struct AcceptanceScene {
    SceneInput input;
    Baked baked;
    SceneSphere sphere;
};

/// Bakes are kept small (4 automatic levels; the generated scene at ~150 triangles per
/// object) so that the whole file runs in about a minute in Release.
const AcceptanceScene& acceptanceScene(const std::string& name) {
    static std::map<std::string, std::unique_ptr<AcceptanceScene>> cache;
    auto& slot = cache[name];
    if (slot) return *slot;
    slot = std::make_unique<AcceptanceScene>();
    SceneRequest request;
    request.name = name;
    request.randomObjects = 400;
    request.randomTriangles = 60000;
    request.sharedDataDir = sharedDataDir().string();
    slot->input = loadScene(request);
    if (slot->input.problem.empty()) {
        slot->baked = bakeScene(slot->input, 4, 2);
        slot->sphere = sceneSphere(slot->input.objects);
    }
    return *slot;
}

#define REQUIRE_ACCEPTANCE_SCENE(s)                                                                  \
    do {                                                                                           \
        if ((s).input.problem.rfind("absent: ", 0) == 0) GTEST_SKIP() << (s).input.problem;        \
        ASSERT_TRUE((s).input.problem.empty()) << (s).input.problem;                               \
        ASSERT_TRUE((s).baked.ok) << (s).input.label << ": " << (s).baked.problem;                 \
    } while (0)

/// The object's shells after welding equal positions (glTF art repeats vertices at seams).
int objectShells(const InputObject& o) { return shellCount(weldedIndices(o.positions, o.indices)); }

/// Uniform double in [0, 1) from the raw engine output (portable across standard libraries).
double uniform01(std::mt19937_64& rng) { return double(rng() >> 11) * 0x1.0p-53; }

// ------------------------------------------------------------------------------------------
// The checks, on any set of proxies standing for sets of originals.

struct ProxyUnderTest {
    uint32_t node = 0;
    const std::vector<float>* positions = nullptr;
    const std::vector<uint32_t>* indices = nullptr;
    std::vector<uint32_t> sources;
    int expectedShells = 0;
    /// A bundle: closed parts that may overlap. Each part must have positive volume, the parts
    /// at least expectedShells, and an original counts as inside when it is inside any part.
    bool unionOfParts = false;
};


struct Figures {
    size_t proxies = 0, notClosed = 0, notEdgeManifold = 0, nonPositiveVolume = 0, shellMismatch = 0, folded = 0;
    size_t verticesChecked = 0, verticesOutside = 0, proxiesWithVerticesOutside = 0;
    double maxVertexOutside = 0;  ///< world units
    size_t rays = 0, raysHittingOriginals = 0, rayViolations = 0, proxiesWithRayViolations = 0;
    size_t rayLateButWithinTolerance = 0;  ///< later along the ray, the hit point within tolerance of the proxy
    double maxRayDepth = 0;  ///< world units: distance outside the proxy of an original point hit first
    std::vector<std::string> examples;  ///< a few nodes per kind of problem
    std::map<std::string, int> examplesOfKind;

    void example(const std::string& kind, const std::string& text) {
        if (examplesOfKind[kind]++ < 3) examples.push_back(text);
    }
    /// Adds a proxy's `count` problems of one kind to `total` (and the proxy to `proxiesWith`).
    void tally(size_t count, size_t& proxiesWith, size_t& total, const std::string& kind, const std::string& text) {
        if (!count) return;
        ++proxiesWith;
        total += count;
        example(kind, text);
    }
    std::string summary() const {
        std::ostringstream s;
        s << proxies << " proxies: " << notClosed << " not closed, " << notEdgeManifold << " not edge-manifold, "
          << folded << " with folded edges, "
          << nonPositiveVolume << " volume <= 0, " << shellMismatch << " shell count != exact aggregate's; "
          << verticesOutside << " of " << verticesChecked << " original vertices outside (in " << proxiesWithVerticesOutside
          << " proxies, max " << maxVertexOutside << "); " << rayViolations << " of " << rays << " rays ("
          << raysHittingOriginals << " hitting originals) reach an original first (in " << proxiesWithRayViolations
          << " proxies, max depth " << maxRayDepth << "; " << rayLateButWithinTolerance
          << " more later along the ray but within tolerance)";
        for (const std::string& e : examples) s << "\n  " << e;
        return s.str();
    }
};

/// Runs the geometric checks on `proxies`, `raysPerScene` rays spread evenly over them.
/// tolerance: world units (1e-5 of the scene's size).
Figures checkProxies(const std::vector<ProxyUnderTest>& proxies, const std::vector<InputObject>& objects,
                     double tolerance, size_t raysPerScene) {
    Figures f;
    const auto device = std::make_shared<RayDevice>();
    std::vector<std::unique_ptr<RayScene>> objectScene;
    for (const InputObject& o : objects) {
        objectScene.push_back(std::make_unique<RayScene>(device));
        objectScene.back()->addMesh(o.positions, o.indices);
        objectScene.back()->commit();
    }
    const size_t raysPerProxy = std::max<size_t>(64, (raysPerScene + proxies.size() - 1) / std::max<size_t>(1, proxies.size()));
    std::mt19937_64 rng(20240601);
    for (const ProxyUnderTest& p : proxies) {
        ++f.proxies;
        const std::string name = "node " + std::to_string(p.node);
        InputObject mesh;
        mesh.positions.assign(p.positions->begin(), p.positions->end());
        mesh.indices.assign(p.indices->begin(), p.indices->end());
        const ClosedCheck closed = checkClosedAfterWeld(mesh);
        if (!closed.problem.empty()) {
            ++f.notClosed;
            f.example("closed", name + ": not closed: " + closed.problem);
        }
        const std::string manifold = edgeManifoldProblem(mesh.indices);
        if (!manifold.empty()) {
            ++f.notEdgeManifold;
            f.example("manifold", name + ": not edge-manifold: " + manifold);
        }
        const size_t folds = foldedEdgeCount(*p.positions, *p.indices);
        if (folds > 0) {
            ++f.folded;
            f.example("folded", name + ": " + std::to_string(folds) + " edges whose faces fold onto each other");
        }
        const std::vector<std::vector<uint32_t>> parts = p.unionOfParts ? shellsOf(mesh.indices) : std::vector<std::vector<uint32_t>>{};
        double volume = signedVolumeOf(mesh);
        for (const std::vector<uint32_t>& part : parts) volume = std::min(volume, signedVolume(mesh.positions, part));
        if (!(volume > 0)) {
            ++f.nonPositiveVolume;
            std::ostringstream text;
            text << name << ": volume " << volume << (p.unionOfParts ? " (smallest part)" : "");
            f.example("volume", text.str());
        }
        const int shells = shellCount(mesh.indices);
        if (p.unionOfParts ? shells < p.expectedShells : shells != p.expectedShells) {
            ++f.shellMismatch;
            f.example("shells", name + ": " + std::to_string(shells) + " shells, exact aggregate " + std::to_string(p.expectedShells));
        }

        // Every original vertex inside or within tolerance of the proxy surface.
        RayScene proxyScene(device);
        proxyScene.addMesh(*p.positions, *p.indices);
        proxyScene.commit();
        std::vector<std::unique_ptr<RayScene>> partScenes;  // a bundle: inside any part
        for (const std::vector<uint32_t>& part : parts) {
            partScenes.push_back(std::make_unique<RayScene>(device));
            partScenes.back()->addMesh(*p.positions, part);
            partScenes.back()->commit();
        }
        const auto inside = [&](const double* q) {
            if (!p.unionOfParts) return proxyScene.insideByParity(q, 0.1 * tolerance);
            return std::any_of(partScenes.begin(), partScenes.end(),
                               [&](const std::unique_ptr<RayScene>& part) { return part->insideByParity(q, 0.1 * tolerance); });
        };
        detail::TriangleBvh proxyBvh;
        proxyBvh.build(mesh.positions.data(), mesh.positions.size() / 3, mesh.indices.data(), mesh.indices.size() / 3);
        size_t outside = 0;
        double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        auto grow = [&](const double* q) {
            for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], q[k]), hi[k] = std::max(hi[k], q[k]);
        };
        for (size_t v = 0; v < mesh.positions.size(); v += 3) grow(&mesh.positions[v]);
        for (uint32_t s : p.sources)
            for (size_t v = 0; v < objects[s].positions.size(); v += 3) {
                const double* q = &objects[s].positions[v];
                grow(q);
                ++f.verticesChecked;
                if (inside(q)) continue;
                const double d = mesh.indices.empty() ? INFINITY : detail::closestPoint(proxyBvh, q).distance;
                if (d <= tolerance) continue;
                ++outside;
                f.maxVertexOutside = std::max(f.maxVertexOutside, d);
            }
        f.tally(outside, f.proxiesWithVerticesOutside, f.verticesOutside, "vertices",
                name + ": " + std::to_string(outside) + " original vertices outside the proxy");

        // Rays from a sphere around the proxy and its originals, aimed at points of their box.
        RayScene originalsScene(device);
        for (uint32_t s : p.sources) originalsScene.addInstance(*objectScene[s]);
        originalsScene.commit();
        double center[3], radius = 0;
        for (int k = 0; k < 3; ++k) {
            center[k] = 0.5 * (lo[k] + hi[k]);
            radius += 0.25 * (hi[k] - lo[k]) * (hi[k] - lo[k]);
        }
        radius = 1.5 * std::sqrt(radius) + tolerance;
        size_t violations = 0;
        for (size_t r = 0; r < raysPerProxy; ++r) {
            double origin[3], target[3], dir[3], len = 0;
            const double z = 2 * uniform01(rng) - 1, phi = 2 * 3.14159265358979323846 * uniform01(rng);
            const double s = std::sqrt(std::max(0.0, 1 - z * z));
            const double u[3] = {s * std::cos(phi), s * std::sin(phi), z};
            for (int k = 0; k < 3; ++k) {
                origin[k] = center[k] + radius * u[k];
                target[k] = lo[k] + (hi[k] - lo[k]) * uniform01(rng);
                dir[k] = target[k] - origin[k];
                len += dir[k] * dir[k];
            }
            len = std::sqrt(len);
            for (double& c : dir) c /= len;
            ++f.rays;
            const float tOriginal = originalsScene.first(origin, dir).t;
            if (!std::isfinite(tOriginal)) continue;
            ++f.raysHittingOriginals;
            const float tProxy = proxyScene.first(origin, dir).t;
            if (double(tProxy) <= double(tOriginal) + tolerance) continue;
            // Later along the ray: a violation when the original point hit lies farther than
            // the tolerance outside the proxy (along a grazing ray a tiny offset gets long).
            double hit[3];
            for (int k = 0; k < 3; ++k) hit[k] = origin[k] + double(tOriginal) * dir[k];
            const double depth = mesh.indices.empty() ? INFINITY : detail::closestPoint(proxyBvh, hit).distance;
            if (depth <= tolerance) {
                ++f.rayLateButWithinTolerance;
                continue;
            }
            ++violations;
            f.maxRayDepth = std::max(f.maxRayDepth, depth);
        }
        f.tally(violations, f.proxiesWithRayViolations, f.rayViolations, "rays",
                name + ": " + std::to_string(violations) + " rays reach an original first");
    }
    return f;
}

/// The non-leaf nodes of a bake as proxies under test.
std::vector<ProxyUnderTest> nodeProxies(const AcceptanceScene& s) {
    std::vector<ProxyUnderTest> out;
    const HierarchyNodes& nodes = s.baked.nodes;
    for (uint32_t i = 0; i < nodes.nodes.size(); ++i) {
        const HierarchyNode& n = nodes.nodes[i];
        if (n.leaf) continue;
        ProxyUnderTest p;
        p.node = i;
        p.positions = &n.positions;
        p.indices = &n.indices;
        p.sources.assign(n.sources.begin(), n.sources.end());
        // A coarser version has the shells of the aggregate it simplifies; a per-object LOD
        // those of its object, or of the solid standing in for an object that is not a
        // closed solid (it is simplified from that solid).
        if (n.objectLod >= 1) {
            const uint32_t object = n.sources.front();
            p.expectedShells = objectShells(s.input.objects[object]);
            // Not a valid closed solid (the module's own test): simplified from its solid.
            detail::PreparedObject prepared;
            std::vector<Diagnostic> ignored;
            const InputObject& o = s.input.objects[object];
            double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
            for (size_t v = 0; v + 2 < o.positions.size(); v += 3)
                for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], o.positions[v + k]), hi[k] = std::max(hi[k], o.positions[v + k]);
            double diagonal2 = 0;
            for (int k = 0; k < 3; ++k) diagonal2 += (hi[k] - lo[k]) * (hi[k] - lo[k]);
            detail::prepareObject(o, 1e-14 * diagonal2, prepared, ignored);  // as objectLodChain does
            if (!prepared.validSolid())
                for (const SolidReport& r : s.baked.hierarchy.solids)
                    if (r.objects == std::vector<uint32_t>{object}) p.expectedShells = shellCount(r.triangles);
        } else if (n.bundleStep >= 1) {  // a bundle: the parts of at least two children (or roots)
            p.unionOfParts = true;
            p.expectedShells = 2;
        } else {
            const HierarchyNode& a = nodes.nodes[aggregateBelow(nodes, i)];
            p.expectedShells = s.baked.hierarchy.levels[size_t(a.firstLevel)].aggregates[a.aggregateIndex].componentCount;
        }
        out.push_back(std::move(p));
    }
    return out;
}

constexpr size_t kRaysPerScene = 20000;  // six scenes: >= 100k rays

void expectClosedAndContaining(const std::string& name) {
    const AcceptanceScene& s = acceptanceScene(name);
    REQUIRE_ACCEPTANCE_SCENE(s);
    const std::vector<ProxyUnderTest> proxies = nodeProxies(s);
    ASSERT_FALSE(proxies.empty());
    const Figures f = checkProxies(proxies, s.input.objects, 1e-5 * s.sphere.diagonal, kRaysPerScene);
    std::printf("%s: %s\n", s.input.label.c_str(), f.summary().c_str());
    ::testing::Test::RecordProperty("proxies", int(f.proxies));
    ::testing::Test::RecordProperty("rays", int(f.rays));
    ::testing::Test::RecordProperty("ray_violations", int(f.rayViolations));
    ::testing::Test::RecordProperty("vertices_outside", int(f.verticesOutside));
    EXPECT_GE(f.rays, kRaysPerScene);
    EXPECT_GT(f.raysHittingOriginals, f.rays / 10) << "rays must mostly test something";
    EXPECT_EQ(f.notClosed, 0u) << f.summary();
    EXPECT_EQ(f.notEdgeManifold, 0u);
    EXPECT_EQ(f.nonPositiveVolume, 0u);
    EXPECT_EQ(f.shellMismatch, 0u);
    EXPECT_EQ(f.verticesOutside, 0u);
    EXPECT_EQ(f.rayViolations, 0u);
}

/// Certified error <= budget for every non-leaf node; on a subset of nodes (small enough for
/// a dense grid: every k-th such node, at most 8; else the smallest node) the brute-force grid measurement of
/// grid_measure.h never exceeds the certified one-sided bounds.
void expectErrorsWithinBudget(const std::string& name) {
    const AcceptanceScene& s = acceptanceScene(name);
    REQUIRE_ACCEPTANCE_SCENE(s);
    const std::vector<HierarchyNode>& nodes = s.baked.nodes.nodes;
    size_t checked = 0, overBudget = 0, noBudget = 0;
    double maxRatio = 0;
    uint32_t worst = 0, fewest = 0;
    size_t fewestTriangles = SIZE_MAX;
    std::vector<uint32_t> small;  // nodes with <= 6000 triangles on both sides together
    for (uint32_t i = 0; i < nodes.size(); ++i) {
        const HierarchyNode& n = nodes[i];
        if (n.leaf) continue;
        ++checked;
        if (!(n.budget > 0)) ++noBudget;
        const double ratio = n.error.bound() / n.budget;
        if (!(n.error.bound() <= n.budget)) ++overBudget;
        if (ratio > maxRatio) maxRatio = ratio, worst = i;
        size_t triangles = n.indices.size() / 3;
        for (uint32_t o : n.sources) triangles += s.input.objects[o].indices.size() / 3;
        if (triangles <= 6000) small.push_back(i);
        if (triangles < fewestTriangles) fewestTriangles = triangles, fewest = i;
    }
    if (small.empty() && checked > 0) small.push_back(fewest);
    const size_t step = std::max<size_t>(1, small.size() / 8);
    const double slack = 1e-6 * s.sphere.diagonal;
    size_t bruteChecked = 0, bruteAbove = 0;
    double bruteWorstExcess = 0;
    for (size_t j = 0; j < small.size() && bruteChecked < 8; j += step) {
        const HierarchyNode& n = nodes[small[j]];
        std::vector<const InputObject*> originals;
        size_t triangles = n.indices.size() / 3;
        for (uint32_t o : n.sources) {
            originals.push_back(&s.input.objects[o]);
            triangles += s.input.objects[o].indices.size() / 3;
        }
        // About 40k grid points over both sides.
        const int grid = std::clamp(int(std::sqrt(80000.0 / double(std::max<size_t>(1, triangles)))), 2, 12);
        const GridMeasured m = gridMeasure(n.positions, n.indices, originals, grid);
        ++bruteChecked;
        const double excess = std::max(m.proxyToOriginals - n.error.proxyToOriginals, m.originalsToProxy - n.error.originalsToProxy);
        if (excess > slack) {
            ++bruteAbove;
            bruteWorstExcess = std::max(bruteWorstExcess, excess);
            std::printf("  node %u: grid (n=%d) %.6g / %.6g above certified %.6g / %.6g\n", small[j], grid, m.proxyToOriginals,
                        m.originalsToProxy, n.error.proxyToOriginals, n.error.originalsToProxy);
        }
    }
    std::printf("%s: %zu non-leaf nodes, %zu over budget (max error/budget %.3g at node %u), %zu without budget; "
                "brute force on %zu nodes: %zu above the certified bound (max excess %.3g)\n",
                s.input.label.c_str(), checked, overBudget, maxRatio, worst, noBudget, bruteChecked, bruteAbove,
                bruteWorstExcess);
    ::testing::Test::RecordProperty("nodes", int(checked));
    ::testing::Test::RecordProperty("over_budget", int(overBudget));
    ::testing::Test::RecordProperty("brute_force_nodes", int(bruteChecked));
    EXPECT_GT(checked, 0u);
    EXPECT_EQ(noBudget, 0u);
    EXPECT_EQ(overBudget, 0u) << "max error / budget " << maxRatio << " at node " << worst;
    EXPECT_GT(bruteChecked, 0u);
    EXPECT_EQ(bruteAbove, 0u) << "max excess " << bruteWorstExcess;
}

/// The exact aggregates of a bake as proxies under test (they hold pointers into `positions`
/// and `indices`, one entry per aggregate of every level).
std::vector<ProxyUnderTest> exactAggregates(const Hierarchy3D& h, std::vector<std::vector<float>>& positions,
                                            std::vector<std::vector<uint32_t>>& indices) {
    std::vector<ProxyUnderTest> out;
    positions.clear();
    indices.clear();
    for (const Level& level : h.levels)
        for (const Aggregate& a : level.aggregates) {
            positions.emplace_back(a.positions.begin(), a.positions.end());
            indices.push_back(a.indices);
        }
    size_t i = 0;
    for (const Level& level : h.levels)
        for (const Aggregate& a : level.aggregates) {
            ProxyUnderTest p;
            p.node = uint32_t(i);
            p.positions = &positions[i];
            p.indices = &indices[i];
            p.sources.assign(a.sourceObjects.begin(), a.sourceObjects.end());
            p.expectedShells = a.componentCount;
            out.push_back(std::move(p));
            ++i;
        }
    return out;
}

/// The exact aggregates (closed, containing their originals by construction) pass every
/// geometric check of the checker.
void expectExactAggregatesPass(const std::string& name, size_t rays) {
    const AcceptanceScene& s = acceptanceScene(name);
    REQUIRE_ACCEPTANCE_SCENE(s);
    std::vector<std::vector<float>> positions;
    std::vector<std::vector<uint32_t>> indices;
    const std::vector<ProxyUnderTest> proxies = exactAggregates(s.baked.hierarchy, positions, indices);
    const Figures exact = checkProxies(proxies, s.input.objects, 1e-5 * s.sphere.diagonal, rays);
    std::printf("%s exact aggregates: %s\n", s.input.label.c_str(), exact.summary().c_str());
    EXPECT_GE(exact.rays, rays);
    EXPECT_GT(exact.raysHittingOriginals, exact.rays / 10);
    EXPECT_EQ(exact.notClosed + exact.notEdgeManifold + exact.nonPositiveVolume + exact.shellMismatch, 0u) << exact.summary();
    EXPECT_EQ(exact.verticesOutside, 0u);
    EXPECT_EQ(exact.rayViolations, 0u);
}

}  // namespace

// Shrunken, holed and inside-out copies of spheres15's exact aggregates fail the checker.
TEST(ProxyAcceptance, CheckerCatchesDamagedProxies) {
    const AcceptanceScene& s = acceptanceScene("spheres15");
    REQUIRE_ACCEPTANCE_SCENE(s);
    std::vector<std::vector<float>> positions;
    std::vector<std::vector<uint32_t>> indices;
    const std::vector<ProxyUnderTest> proxies = exactAggregates(s.baked.hierarchy, positions, indices);
    const size_t count = proxies.size();
    const double tolerance = 1e-5 * s.sphere.diagonal;

    // Shrunk by 2 % about its centroid: original vertices and ray hits outside it.
    for (std::vector<float>& p : positions) {
        double c[3] = {0, 0, 0};
        for (size_t v = 0; v < p.size(); v += 3)
            for (int k = 0; k < 3; ++k) c[k] += p[v + k] / double(p.size() / 3);
        for (size_t v = 0; v < p.size(); v += 3)
            for (int k = 0; k < 3; ++k) p[v + k] = float(c[k] + 0.98 * (p[v + k] - c[k]));
    }
    const Figures shrunk = checkProxies(proxies, s.input.objects, tolerance, 4000);
    std::printf("shrunk: %s\n", shrunk.summary().c_str());
    EXPECT_EQ(shrunk.proxiesWithVerticesOutside, count);
    EXPECT_GT(shrunk.proxiesWithRayViolations, 0u);
    EXPECT_EQ(shrunk.notClosed, 0u);

    // A triangle removed: open. Orientation flipped: negative volume (and still closed).
    size_t i = 0;
    for (const Level& level : s.baked.hierarchy.levels)
        for (const Aggregate& a : level.aggregates) positions[i++].assign(a.positions.begin(), a.positions.end());
    for (i = 0; i < count; ++i) {
        if (i % 2 == 0) indices[i].resize(indices[i].size() - 3);
        else
            for (size_t t = 0; t < indices[i].size(); t += 3) std::swap(indices[i][t + 1], indices[i][t + 2]);
    }
    const Figures damaged = checkProxies(proxies, s.input.objects, tolerance, 1000);
    std::printf("damaged: %s\n", damaged.summary().c_str());
    EXPECT_EQ(damaged.notClosed, (count + 1) / 2);
    EXPECT_EQ(damaged.notEdgeManifold, (count + 1) / 2);
    EXPECT_EQ(damaged.nonPositiveVolume, count / 2);
}

// The scenes, one test (one bake) each. On spheres15 and on the art of truck_town the
// checker is first shown to pass the exact aggregates.
TEST(ProxyAcceptance, Spheres15) {
    expectExactAggregatesPass("spheres15", 10000);
    expectClosedAndContaining("spheres15");
    expectErrorsWithinBudget("spheres15");
}
TEST(ProxyAcceptance, Chess) {
    expectClosedAndContaining("chess");
    expectErrorsWithinBudget("chess");
}
TEST(ProxyAcceptance, Forest) {
    expectClosedAndContaining("forest");
    expectErrorsWithinBudget("forest");
}
TEST(ProxyAcceptance, Village) {
    expectClosedAndContaining("village");
    expectErrorsWithinBudget("village");
}
TEST(ProxyAcceptance, TruckTown) {
    expectExactAggregatesPass("truck_town", 10000);
    expectClosedAndContaining("truck_town");
    expectErrorsWithinBudget("truck_town");
}
TEST(ProxyAcceptance, Random400) {
    expectClosedAndContaining("random");
    expectErrorsWithinBudget("random");
}
