// SPDX-License-Identifier: AGPL-3.0-or-later
// The tiled bake (module/include/aggrelod/tiled_bake_3d.h) on generated open worlds, against
// the untiled bake of the same world in the same run: the cells' levels group objects as the
// untiled bake does (all but the groups near borders of clusters wider than a tile, whose
// share is measured), every cut covers every object exactly once, proxies stay within their
// certified budgets, and the result does not depend on the thread count.
#include "generated_world.h"
#include "hierarchy_serialize.h"
#include "test_support.h"

#include <aggrelod/aggregate3d.h>
#include <aggrelod/hierarchy_nodes.h>
#include <aggrelod/tiled_bake_3d.h>
#include <aggrelod/world.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <map>
#include <mutex>
#include <set>
#include <string>
#include <vector>

using namespace aggrelod;
namespace fs = std::filesystem;

namespace {

std::vector<InputObject> world(uint64_t count, uint32_t seed) { return aggrelod::testing::generatedWorld(count, seed); }

/// The world's terrain tiles and roads as support surfaces (named ones: the generator's
/// terrain is tiled per block, which the automatic rule does not take for a support).
Settings3D worldSettings(const std::vector<InputObject>& objects, std::vector<double> deltas, int threads = 2) {
    Settings3D s;
    s.deltas = std::move(deltas);
    s.threadCount = threads;
    s.support = SupportDetection::Given;
    for (uint32_t i = 0; i < objects.size(); ++i)
        if (objects[i].name.find("terrain") != std::string::npos || objects[i].name.find("road") != std::string::npos)
            s.supportObjects.push_back(i);
    return s;
}

std::set<std::vector<uint32_t>> groupsOf(const Level& level) {
    std::set<std::vector<uint32_t>> groups;
    for (const Aggregate& a : level.aggregates) groups.insert(a.sourceObjects);
    return groups;
}

std::string errors(const Hierarchy3D& h) {
    std::string s;
    for (const Diagnostic& d : h.diagnostics)
        if (d.severity == Diagnostic::Severity::Error) s += d.object + ": " + d.message + "\n";
    return s;
}

}  // namespace

TEST(TiledBake, CellLevelsGroupAsUntiledAndEveryCutCoversEachObjectOnce) {
    const std::vector<double> deltas{0.5, 1, 2, 4, 8, 16};
    for (uint32_t seed : {1u, 7u}) {
        SCOPED_TRACE("seed " + std::to_string(seed));
        const std::vector<InputObject> objects = world(300, seed);
        const Settings3D settings = worldSettings(objects, deltas);
        Hierarchy3D untiled, tiled;
        ASSERT_TRUE(buildHierarchy3D(objects, settings, untiled)) << errors(untiled);
        TiledBakeReport report;
        ASSERT_TRUE(buildTiledHierarchy3D(objects, settings, 48.0, tiled, &report)) << errors(tiled);
        ASSERT_TRUE(report.tiled);
        EXPECT_EQ(report.cellTopDelta, 6.0);
        EXPECT_GT(report.cellCount, 4u);
        EXPECT_GE(report.quadtreeDepth, 1);
        ASSERT_EQ(tiled.levels.size(), untiled.levels.size());
        EXPECT_EQ(tiled.supportObjects, untiled.supportObjects);
        EXPECT_EQ(tiled.inputTriangleCount, untiled.inputTriangleCount);
        EXPECT_NEAR(tiled.originals.volume, untiled.originals.volume, 1e-9 * untiled.originals.volume);

        // The cells' levels: the groups of the untiled bake, but for those near a split cluster.
        for (size_t k = 0; k < tiled.levels.size(); ++k) {
            const std::set<std::vector<uint32_t>> a = groupsOf(untiled.levels[k]), b = groupsOf(tiled.levels[k]);
            size_t differ = 0;
            for (const auto& g : b) differ += a.count(g) ? 0 : 1;
            const double share = double(differ) / double(b.size());
            std::printf("seed %u level %zu delta %g: %zu untiled groups, %zu tiled, %zu differ (%.1f %%)%s\n", seed, k,
                        tiled.levels[k].delta, a.size(), b.size(), differ, 100 * share,
                        tiled.levels[k].delta <= report.cellTopDelta ? " [cell level]" : " [parent level]");
            if (tiled.levels[k].delta <= report.cellTopDelta) {
                if (report.splitClusterCount == 0) {
                    EXPECT_EQ(differ, 0u);
                }
                EXPECT_LE(share, 0.05) << "level " << k;
                EXPECT_GE(b.size(), a.size()) << "a cell level joins no more than the untiled one";
            }
        }

        if (seed != 1) continue;  // the node tree (proxies) once: it is the slow part
        // One node tree: every node's sources are the disjoint union of its children's, so any
        // cut through the tree covers every object exactly once; certified errors within budget.
        HierarchyNodes nodes;
        std::string error;
        ProxySettings proxies;
        proxies.threadCount = 2;
        ASSERT_TRUE(buildHierarchyNodes(tiled, objects, proxies, nodes, error)) << error;
        std::vector<int> covered(objects.size(), 0);
        for (uint32_t r : nodes.roots)
            for (uint32_t o : nodes.nodes[r].sources) ++covered[o];
        for (size_t o = 0; o < objects.size(); ++o)
            if (!std::binary_search(tiled.supportObjects.begin(), tiled.supportObjects.end(), uint32_t(o))) {
                EXPECT_EQ(covered[o], 1) << objects[o].name;
            }
        for (size_t i = nodes.objectCount; i < nodes.nodes.size(); ++i) {
            const HierarchyNode& n = nodes.nodes[i];
            std::vector<uint32_t> union_;
            for (uint32_t c : n.children) union_.insert(union_.end(), nodes.nodes[c].sources.begin(), nodes.nodes[c].sources.end());
            std::sort(union_.begin(), union_.end());
            EXPECT_EQ(union_, n.sources) << "node " << i;
            EXPECT_LE(n.error.bound(), n.budget * (1 + 1e-9)) << "node " << i;
            EXPECT_FALSE(n.indices.empty()) << "node " << i;
        }
    }
}

TEST(TiledBake, SameResultForEveryThreadCount) {
    const std::vector<InputObject> objects = world(200, 3);
    Hierarchy3D one, two;
    ASSERT_TRUE(buildTiledHierarchy3D(objects, worldSettings(objects, {1, 4, 12}, 1), 48.0, one)) << errors(one);
    ASSERT_TRUE(buildTiledHierarchy3D(objects, worldSettings(objects, {1, 4, 12}, 2), 48.0, two)) << errors(two);
    ASSERT_EQ(one.levels.size(), two.levels.size());
    for (size_t k = 0; k < one.levels.size(); ++k) {
        ASSERT_EQ(one.levels[k].aggregates.size(), two.levels[k].aggregates.size());
        for (size_t g = 0; g < one.levels[k].aggregates.size(); ++g) {
            EXPECT_EQ(one.levels[k].aggregates[g].sourceObjects, two.levels[k].aggregates[g].sourceObjects);
            EXPECT_EQ(one.levels[k].aggregates[g].positions, two.levels[k].aggregates[g].positions);
            EXPECT_EQ(one.levels[k].aggregates[g].indices, two.levels[k].aggregates[g].indices);
        }
    }
}

TEST(TiledBake, AutomaticThresholdsSpanCellsAndQuadtree) {
    const std::vector<InputObject> objects = world(200, 5);
    Settings3D settings = worldSettings(objects, {});
    Hierarchy3D h;
    TiledBakeReport report;
    ASSERT_TRUE(buildTiledHierarchy3D(objects, settings, 48.0, h, &report)) << errors(h);
    ASSERT_TRUE(report.tiled);
    size_t cellLevels = 0;
    for (size_t k = 0; k < h.levels.size(); ++k) {
        cellLevels += h.levels[k].delta <= report.cellTopDelta ? 1 : 0;
        if (k) {
            EXPECT_GT(h.levels[k].delta, h.levels[k - 1].delta);
            EXPECT_LE(h.levels[k].aggregates.size(), h.levels[k - 1].aggregates.size());
        }
    }
    EXPECT_GE(cellLevels, 2u);
    EXPECT_EQ(h.levels.size() - cellLevels, size_t(report.quadtreeDepth));
    EXPECT_GT(h.levels.front().aggregates.size(), h.levels.back().aggregates.size());
}

TEST(TiledBake, OneCellIsTheUntiledBake) {
    const std::vector<InputObject> objects = world(60, 2);
    const Settings3D settings = worldSettings(objects, {1, 4});
    Hierarchy3D untiled, tiled;
    TiledBakeReport report;
    ASSERT_TRUE(buildHierarchy3D(objects, settings, untiled));
    ASSERT_TRUE(buildTiledHierarchy3D(objects, settings, 1e6, tiled, &report));
    EXPECT_FALSE(report.tiled);
    ASSERT_EQ(tiled.levels.size(), untiled.levels.size());
    for (size_t k = 0; k < tiled.levels.size(); ++k)
        for (size_t g = 0; g < tiled.levels[k].aggregates.size(); ++g)
            EXPECT_EQ(tiled.levels[k].aggregates[g].positions, untiled.levels[k].aggregates[g].positions);
}

TEST(TiledBake, RefusesBadTileSizesAndThresholdsAboveTheCells) {
    const std::vector<InputObject> objects = world(60, 2);
    Hierarchy3D h;
    EXPECT_FALSE(buildTiledHierarchy3D(objects, worldSettings(objects, {1}), -1.0, h));
    EXPECT_NE(errors(h).find("tile size"), std::string::npos) << errors(h);
    EXPECT_FALSE(buildTiledHierarchy3D(objects, worldSettings(objects, {1}), std::nan(""), h));
    EXPECT_NE(errors(h).find("tile size"), std::string::npos) << errors(h);
    EXPECT_FALSE(buildTiledHierarchy3D(objects, worldSettings(objects, {20, 40}), 48.0, h));
    EXPECT_NE(errors(h).find("at most 6"), std::string::npos) << errors(h);
    EXPECT_TRUE(h.levels.empty());
}

namespace {

/// A TileCache in memory; safe to call from several threads (as the proxies stage does).
struct MemoryCache {
    std::map<std::string, std::vector<uint8_t>> entries;
    std::mutex mutex;
    TileCache cache() {
        TileCache c;
        c.load = [this](const std::string& key, std::vector<uint8_t>& bytes) {
            std::lock_guard<std::mutex> lock(mutex);
            auto it = entries.find(key);
            if (it == entries.end()) return false;
            bytes = it->second;
            return true;
        };
        c.store = [this](const std::string& key, const std::vector<uint8_t>& bytes) {
            std::lock_guard<std::mutex> lock(mutex);
            entries[key] = bytes;
            return true;
        };
        return c;
    }
};

void expectSameLevels(const Hierarchy3D& a, const Hierarchy3D& b) {
    ASSERT_EQ(a.levels.size(), b.levels.size());
    for (size_t k = 0; k < a.levels.size(); ++k) {
        ASSERT_EQ(a.levels[k].aggregates.size(), b.levels[k].aggregates.size()) << "level " << k;
        for (size_t g = 0; g < a.levels[k].aggregates.size(); ++g) {
            const Aggregate &x = a.levels[k].aggregates[g], &y = b.levels[k].aggregates[g];
            EXPECT_EQ(x.sourceObjects, y.sourceObjects);
            EXPECT_EQ(x.positions, y.positions);
            EXPECT_EQ(x.indices, y.indices);
            EXPECT_EQ(x.faceColors, y.faceColors);
        }
    }
    EXPECT_EQ(a.objectModel, b.objectModel);
    EXPECT_EQ(a.supportObjects, b.supportObjects);
    EXPECT_EQ(a.diagnostics.size(), b.diagnostics.size());
}

}  // namespace

TEST(TiledBake, CacheRebakesOnlyTheChangedCellAndItsParents) {
    std::vector<InputObject> objects = world(200, 3);
    const Settings3D settings = worldSettings(objects, {1, 4, 12, 24});
    MemoryCache memory;
    const TileCache cache = memory.cache();
    TiledBakeOptions options;
    options.tileSize = 48;
    options.cache = &cache;
    Hierarchy3D first, again, plain;
    TiledBakeReport r1, r2;
    ASSERT_TRUE(buildTiledHierarchy3D(objects, settings, options, first, &r1)) << errors(first);
    EXPECT_EQ(r1.cellsBaked, r1.cellCount);
    EXPECT_EQ(r1.cellsLoaded, 0u);
    ASSERT_TRUE(buildTiledHierarchy3D(objects, settings, options, again, &r2)) << errors(again);
    EXPECT_EQ(r2.cellsBaked + r2.parentsBaked, 0u);
    EXPECT_EQ(r2.cellsLoaded, r1.cellsBaked);
    EXPECT_EQ(r2.parentsLoaded, r1.parentsBaked);
    expectSameLevels(first, again);
    ASSERT_TRUE(buildTiledHierarchy3D(objects, settings, 48.0, plain));
    expectSameLevels(first, plain);

    // Move one object by 2 cm: only its cell and the parent cells above it are baked again.
    size_t moved = 0;
    while (moved + 1 < objects.size() && std::binary_search(settings.supportObjects.begin(), settings.supportObjects.end(),
                                                            uint32_t(moved)))
        ++moved;
    ASSERT_FALSE(std::binary_search(settings.supportObjects.begin(), settings.supportObjects.end(), uint32_t(moved)));
    for (size_t i = 0; i < objects[moved].positions.size(); i += 3) objects[moved].positions[i] += 0.02;
    Hierarchy3D changed, fresh;
    TiledBakeReport r3;
    ASSERT_TRUE(buildTiledHierarchy3D(objects, settings, options, changed, &r3)) << errors(changed);
    EXPECT_EQ(r3.cellsBaked, 1u);
    EXPECT_EQ(r3.cellsLoaded, r1.cellsBaked - 1);
    EXPECT_LE(r3.parentsBaked, size_t(r3.quadtreeDepth) * 2);  // one parent per quadtree level and delta band
    EXPECT_GT(r3.parentsLoaded, 0u);
    std::printf("moved %s: %zu of %zu cells and %zu of %zu parent cells baked again\n", objects[moved].name.c_str(),
                r3.cellsBaked, r3.cellsBaked + r3.cellsLoaded, r3.parentsBaked, r3.parentsBaked + r3.parentsLoaded);
    ASSERT_TRUE(buildTiledHierarchy3D(objects, settings, 48.0, fresh));
    expectSameLevels(changed, fresh);

    // A corrupted entry is refused and its piece baked again, with the same result.
    for (auto& [key, bytes] : memory.entries) bytes[bytes.size() / 2] ^= 0x5a, bytes.resize(bytes.size() - 1);
    Hierarchy3D repaired;
    TiledBakeReport r4;
    ASSERT_TRUE(buildTiledHierarchy3D(objects, settings, options, repaired, &r4)) << errors(repaired);
    EXPECT_EQ(r4.cellsLoaded + r4.parentsLoaded, 0u);
    expectSameLevels(repaired, fresh);
}

TEST(TiledBake, PiecesBakedApartGiveTheWholeBake) {
    const std::vector<InputObject> objects = world(200, 6);
    for (const std::vector<double>& deltas : {std::vector<double>{1, 4, 12, 24}, std::vector<double>{}}) {
        SCOPED_TRACE(deltas.empty() ? "automatic thresholds" : "explicit thresholds");
        const Settings3D settings = worldSettings(objects, deltas);
        MemoryCache memory;
        const TileCache cache = memory.cache();
        TiledBakeOptions options;
        options.tileSize = 48;
        options.cache = &cache;
        options.task.kind = TileTask::Kind::Plan;
        // One layout for every piece, as in a list of pieces in one process: the whole bake from
        // their cache entries is still the plain bake (checked at the end).
        options.layout = newTiledLayout();
        Hierarchy3D h;
        TiledBakeReport plan;
        ASSERT_TRUE(buildTiledHierarchy3D(objects, settings, options, h, &plan)) << errors(h);
        ASSERT_TRUE(plan.tiled);
        {
            // A layout kept for another tile size or other objects is not reused.
            TiledBakeOptions other = options;
            other.layout = newTiledLayout();
            TiledBakeReport at48, at24, fresh24, moved;
            ASSERT_TRUE(buildTiledHierarchy3D(objects, settings, other, h, &at48)) << errors(h);
            other.tileSize = 24;
            ASSERT_TRUE(buildTiledHierarchy3D(objects, settings, other, h, &at24)) << errors(h);
            TiledBakeOptions alone = other;
            alone.layout = nullptr;
            ASSERT_TRUE(buildTiledHierarchy3D(objects, settings, alone, h, &fresh24)) << errors(h);
            EXPECT_GT(at24.columns, at48.columns);
            EXPECT_EQ(at24.columns, fresh24.columns);
            EXPECT_EQ(at24.cells, fresh24.cells);
            std::vector<InputObject> stretched = objects;  // as many objects, twice as far apart
            for (InputObject& o : stretched)
                for (size_t i = 0; i < o.positions.size(); i += 3) o.positions[i] *= 2;
            ASSERT_TRUE(buildTiledHierarchy3D(stretched, settings, other, h, &moved)) << errors(h);
            TiledBakeReport movedFresh;
            ASSERT_TRUE(buildTiledHierarchy3D(stretched, settings, alone, h, &movedFresh)) << errors(h);
            EXPECT_GT(moved.columns, at24.columns);
            EXPECT_EQ(moved.columns, movedFresh.columns);
            EXPECT_EQ(moved.cells, movedFresh.cells);
        }
        ASSERT_FALSE(plan.cells.empty());
        EXPECT_TRUE(h.levels.empty());
        EXPECT_EQ(plan.automaticDeltas, deltas.empty());

        // A parent before its cells: refused, naming what is missing.
        for (size_t j = 1; j < plan.parents.size(); ++j)
            if (!plan.parents[j].empty()) {
                options.task = TileTask{TileTask::Kind::Parent, 0, int(j), plan.parents[j][0].first, plan.parents[j][0].second};
                EXPECT_FALSE(buildTiledHierarchy3D(objects, settings, options, h));
                EXPECT_NE(errors(h).find("the tile cache holds no result for"), std::string::npos) << errors(h);
                break;
            }
        // Graphs, cells, then parents level by level (the order aggrelod-farm runs them in).
        if (plan.automaticDeltas)
            for (uint32_t cell : plan.cells) {
                options.task = TileTask{TileTask::Kind::Graph, cell, 0, 0, 0};
                ASSERT_TRUE(buildTiledHierarchy3D(objects, settings, options, h)) << errors(h);
            }
        for (uint32_t cell : plan.cells) {
            options.task = TileTask{TileTask::Kind::Cell, cell, 0, 0, 0};
            ASSERT_TRUE(buildTiledHierarchy3D(objects, settings, options, h)) << errors(h);
        }
        for (size_t j = 1; j < plan.parents.size(); ++j)
            for (const auto& [row, column] : plan.parents[j]) {
                options.task = TileTask{TileTask::Kind::Parent, 0, int(j), row, column};
                ASSERT_TRUE(buildTiledHierarchy3D(objects, settings, options, h)) << errors(h);
            }
        options.task = TileTask{};
        Hierarchy3D whole, plain;
        TiledBakeReport report;
        ASSERT_TRUE(buildTiledHierarchy3D(objects, settings, options, whole, &report)) << errors(whole);
        EXPECT_EQ(report.graphsBaked + report.cellsBaked + report.parentsBaked, 0u) << "every piece was in the cache";
        ASSERT_TRUE(buildTiledHierarchy3D(objects, settings, 48.0, plain)) << errors(plain);
        expectSameLevels(whole, plain);
    }
}

TEST(TiledBakeCli, OptionsErrorsPlanAndCachedRebake) {
    const auto dir = aggrelod::testing::freshTestDir("tiled_bake_cli");
    const std::string scene = (dir / "world.glb").string();
    ASSERT_EQ(aggrelod::testing::runProgram({AGGRELOD_MAKE_SAMPLE, "world", "--objects", "120", "-o", scene}, dir).exitCode, 0);
    const auto bake = [&](std::vector<std::string> extra) {
        std::vector<std::string> argv{AGGRELOD_CLI, "bake", scene, "-o", (dir / "out").string(), "--support", "terrain|road"};
        argv.insert(argv.end(), extra.begin(), extra.end());
        return aggrelod::testing::runProgram(argv, dir);
    };
    // Usage errors (exit 1) and a bake that cannot be tiled as asked (exit 3), each saying why.
    const struct {
        std::vector<std::string> args;
        int exitCode;
        const char* says;
    } bad[] = {
        {{"--tile-size", "0"}, 1, "expects 'auto' or a length > 0"},
        {{"--tile-size", "nan"}, 1, "expects 'auto' or a length > 0"},
        {{"--tile-cache", (dir / "c").string()}, 1, "--tile-cache needs --tile-size"},
        {{"--tile-task", "plan"}, 1, "--tile-task needs --tile-size"},
        {{"--tile-size", "48", "--tile-task", "cell:0"}, 1, "needs --tile-cache"},
        {{"--tile-size", "48", "--tile-cache", (dir / "c").string(), "--tile-task", "cell:x"}, 1, "expects plan, graph:N"},
        {{"--tile-size", "48", "--tile-cache", (dir / "c").string(), "--tile-task", "proxies:3:0:2"}, 1, "PHASE 1 or 2"},
        {{"--tile-size", "48", "--tile-cache", (dir / "c").string(), "--tile-task", "proxies:1:2:2"}, 1, "PART below PARTS"},
        {{"--tile-size", "48", "--tile-cache", (dir / "c").string(), "--tile-task", "proxies:1:0:2"}, 3,
         "the tile cache holds no result for"},
        {{"--tile-size", "48", "--tile-cache", (dir / "c").string(), "--tile-task", "cell:0,proxies:1:0:2"}, 1,
         "or a comma-separated list of graph, cell and parent pieces"},
        {{"--tile-size", "48", "--tile-cache", (dir / "c").string(), "--tile-task", "cell:0,"}, 1, "expects plan"},
        {{"--tile-size", "48", "--delta", "20"}, 3, "needs a delta of at most 6"},
        {{"--tile-size", "48", "--tile-cache", (dir / "c").string(), "--tile-task", "parent:1:0:0"}, 3,
         "the tile cache holds no result for"},
    };
    for (const auto& b : bad) {
        const auto r = bake(b.args);
        EXPECT_EQ(r.exitCode, b.exitCode) << r.describe();
        EXPECT_NE(r.err.find(b.says), std::string::npos) << r.describe();
    }
    EXPECT_FALSE(fs::exists(dir / "out" / "scene.aglod")) << "a failed or partial run writes no outputs";

    const auto plan = bake({"--tile-size", "48", "--tile-task", "plan", "--quiet"});
    ASSERT_EQ(plan.exitCode, 0) << plan.describe();
    EXPECT_EQ(plan.out.rfind("{\"tiled\":true,\"graphs\":true,\"cells\":[", 0), 0u) << plan.out;
    EXPECT_NE(plan.out.find("\"parents\":[[1,"), std::string::npos) << plan.out;

    // Every cell in one process (a comma-separated list, as aggrelod-farm batches them): all
    // baked into the cache, so that the whole bake then bakes no cell.
    {
        const std::string cells = plan.out.substr(plan.out.find("\"cells\":[") + 9,
                                                  plan.out.find(']', plan.out.find("\"cells\":[")) - plan.out.find("\"cells\":[") - 9);
        std::string list;
        for (size_t at = 0; at < cells.size();) {
            const size_t comma = std::min(cells.find(',', at), cells.size());
            list += (list.empty() ? "cell:" : ",cell:") + cells.substr(at, comma - at);
            at = comma + 1;
        }
        const std::vector<std::string> listed{"--tile-size", "48", "--tile-cache", (dir / "listed").string(), "--delta", "1,4,12"};
        std::vector<std::string> args = listed;
        args.insert(args.end(), {"--tile-task", list});
        const auto batch = bake(args);
        ASSERT_EQ(batch.exitCode, 0) << batch.describe();
        const size_t cellCount = std::count(list.begin(), list.end(), ',') + 1;
        EXPECT_NE(batch.out.find(": " + std::to_string(cellCount) + " pieces baked, 0 read"), std::string::npos) << batch.out;
        const auto whole = bake(listed);
        ASSERT_EQ(whole.exitCode, 0) << whole.describe();
        EXPECT_NE(whole.out.find("tiles: 0 cells and "), std::string::npos) << whole.out;
    }

    const std::vector<std::string> cached{"--tile-size", "48", "--tile-cache", (dir / "cache").string(), "--delta", "1,4,12"};
    const auto first = bake(cached);
    ASSERT_EQ(first.exitCode, 0) << first.describe();
    EXPECT_NE(first.out.find(" read from "), std::string::npos) << first.out;
    const std::string aglod = aggrelod::testing::readFile(dir / "out" / "scene.aglod");
    const std::string levels = aggrelod::testing::readFile(dir / "out" / "levels.glb");
    // Every piece in the cache: the hierarchy is held without its exact meshes, which the
    // bounds and levels.glb read back from the cache. The same files.
    const auto second = bake(cached);
    ASSERT_EQ(second.exitCode, 0) << second.describe();
    EXPECT_NE(second.out.find("tiles: 0 cells and 0 parent cells baked"), std::string::npos) << second.out;
    EXPECT_NE(second.out.find("proxies: 0 items made"), std::string::npos) << second.out;
    EXPECT_EQ(aggrelod::testing::readFile(dir / "out" / "scene.aglod"), aglod) << "a cached rebake gives the same file";
    EXPECT_EQ(aggrelod::testing::readFile(dir / "out" / "levels.glb"), levels) << "a cached rebake gives the same file";
#ifdef AGGRELOD_CLI_ASAN
    // Damaged cache files through the AddressSanitizer build of the CLI: refused, baked again,
    // same outputs, no sanitizer report (which would end the process with an error).
    for (const auto& entry : fs::directory_iterator(dir / "cache")) {
        std::string bytes = aggrelod::testing::readFile(entry.path());
        bytes.resize(bytes.size() * 2 / 3);
        if (!bytes.empty()) bytes[bytes.size() / 2] ^= 0x33;
        aggrelod::testing::writeFile(entry.path(), bytes);
    }
    std::vector<std::string> argv{AGGRELOD_CLI_ASAN, "bake", scene, "-o", (dir / "out").string(), "--support", "terrain|road"};
    argv.insert(argv.end(), cached.begin(), cached.end());
    const auto sanitized = aggrelod::testing::runProgram(argv, dir);
    ASSERT_EQ(sanitized.exitCode, 0) << sanitized.describe();
    EXPECT_EQ(sanitized.err.find("AddressSanitizer"), std::string::npos) << sanitized.describe();
    EXPECT_NE(sanitized.out.find(" and 0 read from"), std::string::npos) << sanitized.out;
    EXPECT_NE(sanitized.out.find(" items made, 0 read"), std::string::npos) << sanitized.out;
    EXPECT_EQ(aggrelod::testing::readFile(dir / "out" / "scene.aglod"), aglod);
#endif
}

TEST(TiledBake, CacheEntriesRoundTripAndDamagedOnesAreRefused) {
    const std::vector<InputObject> objects = world(40, 2);
    Hierarchy3D h;
    ASSERT_TRUE(buildHierarchy3D(objects, worldSettings(objects, {1, 4}), h)) << errors(h);
    std::vector<uint8_t> bytes;
    detail::serializeHierarchy(h, bytes);
    Hierarchy3D back;
    ASSERT_TRUE(detail::deserializeHierarchy(bytes, back));
    std::vector<uint8_t> again;
    detail::serializeHierarchy(back, again);
    EXPECT_EQ(again, bytes);
    expectSameLevels(h, back);
    // Every truncation is refused; a flipped byte is refused or read as a result of the same
    // layout (written again, it has the same size: no count was misread).
    for (size_t cut = 0; cut < bytes.size(); cut += std::max<size_t>(1, bytes.size() / 997)) {
        const std::vector<uint8_t> shorter(bytes.begin(), bytes.begin() + cut);
        EXPECT_FALSE(detail::deserializeHierarchy(shorter, back)) << "cut at " << cut;
        EXPECT_TRUE(back.levels.empty());
    }
    std::vector<uint8_t> longer = bytes;
    longer.push_back(0);
    EXPECT_FALSE(detail::deserializeHierarchy(longer, back));
    for (size_t at = 0; at < bytes.size(); at += std::max<size_t>(1, bytes.size() / 499)) {
        std::vector<uint8_t> flipped = bytes;
        flipped[at] ^= 0xff;
        if (!detail::deserializeHierarchy(flipped, back)) continue;
        std::vector<uint8_t> rewritten;
        detail::serializeHierarchy(back, rewritten);
        EXPECT_EQ(rewritten.size(), flipped.size()) << "flipped byte " << at;
    }
}

namespace {

void expectSameNodes(const HierarchyNodes& a, const HierarchyNodes& b) {
    ASSERT_EQ(a.nodes.size(), b.nodes.size());
    EXPECT_EQ(a.roots, b.roots);
    EXPECT_EQ(a.nodeOfAggregate, b.nodeOfAggregate);
    for (size_t i = 0; i < a.nodes.size(); ++i) {
        const HierarchyNode &x = a.nodes[i], &y = b.nodes[i];
        SCOPED_TRACE("node " + std::to_string(i));
        EXPECT_EQ(x.parent, y.parent);
        EXPECT_EQ(x.children, y.children);
        EXPECT_EQ(x.sources, y.sources);
        EXPECT_EQ(x.objectLod, y.objectLod);
        EXPECT_EQ(x.coarserStep, y.coarserStep);
        EXPECT_EQ(x.positions, y.positions);
        EXPECT_EQ(x.indices, y.indices);
        EXPECT_EQ(x.faceColors, y.faceColors);
        EXPECT_EQ(x.error.bound(), y.error.bound());
        EXPECT_EQ(x.budget, y.budget);
        EXPECT_EQ(x.geometricError, y.geometricError);
        EXPECT_EQ(x.sphereRadius, y.sphereRadius);
        EXPECT_EQ(x.exactTriangleCount, y.exactTriangleCount);
        if (::testing::Test::HasFailure()) return;  // one node's differences say enough
    }
}

}  // namespace

// The proxies stage with a cache (ProxySettings::cache): the same nodes when shared out in
// phases and parts (as aggrelod-farm runs it), when read back whole, after a local change
// (only the items that depend on the moved object are made again) and from damaged entries.
TEST(ProxyCache, SharesRebakesAndDamagedEntriesGiveTheSameNodes) {
    std::vector<InputObject> objects = world(200, 3);
    const Settings3D settings = worldSettings(objects, {1, 4, 12, 24});
    Hierarchy3D h;
    ASSERT_TRUE(buildTiledHierarchy3D(objects, settings, 48.0, h)) << errors(h);
    ProxySettings proxies;
    proxies.threadCount = 2;
    HierarchyNodes plain;
    std::string error;
    ASSERT_TRUE(buildHierarchyNodes(h, objects, proxies, plain, error)) << error;
    EXPECT_GT(plain.proxyItemsMade, 0u);
    EXPECT_EQ(plain.proxyItemsLoaded, 0u) << "no cache, nothing read";

    MemoryCache memory;
    const TileCache cache = memory.cache();
    ProxySettings cached = proxies;
    cached.cache = &cache;
    // Refused: phase 2 before phase 1 (naming the missing item), no cache, a share out of range.
    EXPECT_FALSE(buildProxyShare(h, objects, cached, ProxyShare{2, 0, 3}, error));
    EXPECT_NE(error.find("the cache holds no result for the proxy of level"), std::string::npos) << error;
    EXPECT_FALSE(buildProxyShare(h, objects, proxies, ProxyShare{1, 0, 1}, error));
    EXPECT_NE(error.find("needs a cache"), std::string::npos) << error;
    EXPECT_FALSE(buildProxyShare(h, objects, cached, ProxyShare{1, 3, 3}, error));
    EXPECT_NE(error.find("out of range"), std::string::npos) << error;

    size_t sharedMade = 0, preparedInPhaseOne = 0;
    for (int phase : {1, 2})
        for (uint32_t part = 0; part < 3; ++part) {
            size_t made = 0, loaded = 0, prepared = 0;
            ASSERT_TRUE(buildProxyShare(h, objects, cached, ProxyShare{phase, part, 3}, error, &made, &loaded, &prepared))
                << error;
            EXPECT_GT(made, 0u) << "phase " << phase << " part " << part;
            sharedMade += made;
            std::printf("phase %d share %u: %zu items made, %zu of %zu originals prepared\n", phase, part, made, prepared,
                        objects.size());
            if (phase == 1) preparedInPhaseOne += prepared;
        }
    // A share takes one part of the world: it measures against the originals there (and those
    // of the large groups it holds), not against most of them (here 290 in all against 372 for
    // items dealt out by work alone, one group of 150 objects in either case). Each support
    // surface is prepared once more, by the share that makes its versions.
    std::printf("%zu support surfaces\n", settings.supportObjects.size());
    EXPECT_LT((preparedInPhaseOne - settings.supportObjects.size()) * 5, objects.size() * 8);
    HierarchyNodes whole;
    ASSERT_TRUE(buildHierarchyNodes(h, objects, cached, whole, error)) << error;
    EXPECT_EQ(whole.proxyItemsMade, 0u) << "the shares made every item";
    EXPECT_GE(sharedMade, whole.proxyItemsLoaded);
    expectSameNodes(whole, plain);

    // Move one object by 2 cm: only the items whose input changed (the nodes holding it, and
    // those of the parent cells baked again) are made again.
    size_t moved = 0;
    while (std::binary_search(settings.supportObjects.begin(), settings.supportObjects.end(), uint32_t(moved))) ++moved;
    for (size_t i = 0; i < objects[moved].positions.size(); i += 3) objects[moved].positions[i] += 0.02;
    Hierarchy3D changed;
    ASSERT_TRUE(buildTiledHierarchy3D(objects, settings, 48.0, changed)) << errors(changed);
    HierarchyNodes rebaked, fresh;
    ASSERT_TRUE(buildHierarchyNodes(changed, objects, cached, rebaked, error)) << error;
    ASSERT_TRUE(buildHierarchyNodes(changed, objects, proxies, fresh, error)) << error;
    std::printf("moved %s: %zu proxy items made again, %zu read back\n", objects[moved].name.c_str(),
                rebaked.proxyItemsMade, rebaked.proxyItemsLoaded);
    EXPECT_GT(rebaked.proxyItemsMade, 0u);
    EXPECT_LT(rebaked.proxyItemsMade * 4, rebaked.proxyItemsMade + rebaked.proxyItemsLoaded);
    expectSameNodes(rebaked, fresh);

    // Damaged entries (cut short, and a byte flipped) are refused and made again: the same
    // nodes. (Entries carry no checksum: a flipped coordinate alone would be read back.)
    for (auto& [key, bytes] : memory.entries) {
        bytes.resize(bytes.size() * 2 / 3);
        if (!bytes.empty()) bytes[bytes.size() / 2] ^= 0x5a;
    }
    HierarchyNodes repaired;
    ASSERT_TRUE(buildHierarchyNodes(changed, objects, cached, repaired, error)) << error;
    EXPECT_EQ(repaired.proxyItemsLoaded, 0u);
    expectSameNodes(repaired, fresh);
}

// A share of the proxies holds the hierarchy without its meshes (TiledBakeOptions::leanMeshes:
// a 65,536-object world's exact aggregates are 1.4 GiB) and reads again from the tile cache
// only the meshes of the items it makes: the same nodes as the proxies made whole; a piece gone
// from the cache fails the share, naming it.
TEST(ProxyCache, LeanSharesReadTheirOwnMeshesAndGiveTheSameNodes) {
    const std::vector<InputObject> objects = world(200, 3);
    const Settings3D settings = worldSettings(objects, {1, 4, 12, 24});
    MemoryCache memory;
    const TileCache cache = memory.cache();
    TiledBakeOptions options;
    options.tileSize = 48;
    options.cache = &cache;
    Hierarchy3D h;
    ASSERT_TRUE(buildTiledHierarchy3D(objects, settings, options, h)) << errors(h);
    const std::map<std::string, std::vector<uint8_t>> pieces = memory.entries;  // the tile pieces alone
    ProxySettings proxies;
    proxies.threadCount = 2;
    HierarchyNodes plain;
    std::string error;
    ASSERT_TRUE(buildHierarchyNodes(h, objects, proxies, plain, error)) << error;

    options.task.kind = TileTask::Kind::Assemble;
    options.leanMeshes = true;
    Hierarchy3D lean;
    ASSERT_TRUE(buildTiledHierarchy3D(objects, settings, options, lean)) << errors(lean);
    ASSERT_EQ(lean.levels.size(), h.levels.size());
    size_t aggregates = 0;
    for (size_t k = 0; k < h.levels.size(); ++k) {
        ASSERT_EQ(lean.levels[k].aggregates.size(), h.levels[k].aggregates.size());
        EXPECT_EQ(lean.levels[k].triangleCount, h.levels[k].triangleCount);
        for (size_t g = 0; g < h.levels[k].aggregates.size(); ++g) {
            const Aggregate& a = lean.levels[k].aggregates[g];
            const Aggregate& full = h.levels[k].aggregates[g];
            ASSERT_TRUE(a.meshInCache) << "level " << k << " aggregate " << g;
            EXPECT_TRUE(a.positions.empty() && a.indices.empty() && a.faceColors.empty());
            EXPECT_EQ(a.sourceObjects, full.sourceObjects);
            EXPECT_EQ(a.meshInCache->triangleCount, full.indices.size() / 3);
            EXPECT_EQ(aggregateMeshHash(a), aggregateMeshHash(full));
            uint64_t x[2], y[2];
            aggregateVertexSetHash(a, x);
            aggregateVertexSetHash(full, y);
            EXPECT_TRUE(x[0] == y[0] && x[1] == y[1]);
            ++aggregates;
        }
    }
    EXPECT_GT(aggregates, 100u);

    ProxySettings cached = proxies;
    cached.cache = &cache;
    {  // a piece gone: the share says which entry
        MemoryCache damaged;
        damaged.entries = pieces;
        const std::string gone = lean.levels[0].aggregates[0].meshInCache->piece;
        ASSERT_EQ(damaged.entries.erase(gone), 1u);
        const TileCache damagedCache = damaged.cache();
        ProxySettings withDamaged = proxies;
        withDamaged.cache = &damagedCache;
        EXPECT_FALSE(buildProxyShare(lean, objects, withDamaged, ProxyShare{1, 0, 1}, error));
        EXPECT_NE(error.find(gone), std::string::npos) << error;
    }
    for (int phase : {1, 2})
        for (uint32_t part = 0; part < 3; ++part)
            ASSERT_TRUE(buildProxyShare(lean, objects, cached, ProxyShare{phase, part, 3}, error)) << error;
    HierarchyNodes whole;
    ASSERT_TRUE(buildHierarchyNodes(h, objects, cached, whole, error)) << error;
    EXPECT_EQ(whole.proxyItemsMade, 0u) << "the lean shares made every item";
    expectSameNodes(whole, plain);
    // The whole stage on the lean hierarchy, as the bake's last step runs it when every piece
    // is in the cache: the nodes' bounds read the exact meshes back. The same nodes.
    HierarchyNodes fromLean;
    ASSERT_TRUE(buildHierarchyNodes(lean, objects, cached, fromLean, error)) << error;
    expectSameNodes(fromLean, plain);
    // A piece whose aggregate changed after the assembly (an index far out of range): refused,
    // naming the piece, never read out of bounds.
    const Aggregate* group = nullptr;  // the finest aggregate of several objects: a node of its own
    for (const Level& level : lean.levels)
        for (const Aggregate& a : level.aggregates)
            if (!group && a.sourceObjects.size() > 1) group = &a;
    ASSERT_NE(group, nullptr);
    const std::string changed = group->meshInCache->piece;
    Hierarchy3D piece;
    ASSERT_TRUE(detail::deserializeHierarchy(memory.entries.at(changed), piece));
    piece.levels[group->meshInCache->level].aggregates[group->meshInCache->index].indices.front() = 1000000000u;
    memory.entries[changed].clear();
    detail::serializeHierarchy(piece, memory.entries[changed]);
    HierarchyNodes refused;
    EXPECT_FALSE(buildHierarchyNodes(lean, objects, cached, refused, error));
    EXPECT_NE(error.find(changed), std::string::npos) << error;
}
