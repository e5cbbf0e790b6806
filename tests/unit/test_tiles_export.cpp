// SPDX-License-Identifier: AGPL-3.0-or-later
// 3D Tiles export (`aggrelod bake --tiles`, bake/tiles_export.cpp):
//  - the axis convention and the box / error mapping on a hand-made hierarchy;
//  - a sample scene baked with --tiles: tileset.json structure (errors monotone, children
//    boxes inside parents, REPLACE, leaves with error 0) and every tile GLB through the
//    Khronos glTF validator, both by tests/web/check_tileset.mjs (which is shown to catch
//    broken tilesets); byte-identical tiles for one and two threads.
#include "json.h"
#include "scene_io.h"
#include "test_support.h"
#include "tiles_export.h"

#include <aggrelod/samples.h>

#include <gtest/gtest.h>

#include <limits>
#include <regex>
#include <string>
#include <vector>

using namespace aggrelod;
using namespace aggrelod::testing;

namespace {

/// A leaf node: an axis-aligned box object from lo to hi.
HierarchyNode boxLeaf(uint32_t index, const double lo[3], const double hi[3]) {
    const InputObject box = samples::makeBox("b", {lo[0], lo[1], lo[2]}, {hi[0], hi[1], hi[2]});
    HierarchyNode n;
    n.leaf = true;
    n.sources = {index};
    n.positions.assign(box.positions.begin(), box.positions.end());
    n.indices = box.indices;
    for (int k = 0; k < 3; ++k) {
        n.boundsMin[k] = lo[k];
        n.boundsMax[k] = hi[k];
    }
    return n;
}

/// Two boxes and one aggregate above them (error 0.5).
void makeTwoBoxHierarchy(HierarchyNodes& nodes, std::vector<InputObject>& objects) {
    const double lo0[3] = {0, 0, 0}, hi0[3] = {1, 2, 3};
    const double lo1[3] = {2, 0, 0}, hi1[3] = {3, 1, 1};
    objects = {samples::makeBox("left", {0, 0, 0}, {1, 2, 3}), samples::makeBox("right", {2, 0, 0}, {3, 1, 1})};
    objects[1].id = 7;
    nodes.objectCount = 2;
    nodes.nodes = {boxLeaf(0, lo0, hi0), boxLeaf(1, lo1, hi1)};
    HierarchyNode parent;
    parent.children = {0, 1};
    parent.sources = {0, 1};
    parent.firstLevel = parent.lastLevel = 0;
    parent.delta = 1;
    parent.geometricError = 0.5;
    const InputObject hull = samples::makeBox("hull", {0, 0, 0}, {3, 2, 3});
    parent.positions.assign(hull.positions.begin(), hull.positions.end());
    parent.indices = hull.indices;
    for (int k = 0; k < 3; ++k) {
        parent.boundsMin[k] = 0;
        parent.boundsMax[k] = k == 0 ? 3 : (k == 1 ? 2 : 3);
    }
    nodes.nodes.push_back(parent);
    nodes.nodes[0].parent = nodes.nodes[1].parent = 2;
    nodes.roots = {2};
}

/// The 12 numbers of every "box" in `json`, in order of appearance.
std::vector<std::vector<double>> boxesOf(const std::string& json) {
    std::vector<std::vector<double>> boxes;
    const std::regex boxRegex("\"box\": \\[([^\\]]*)\\]");
    for (auto it = std::sregex_iterator(json.begin(), json.end(), boxRegex); it != std::sregex_iterator(); ++it) {
        std::vector<double> values;
        std::stringstream s((*it)[1].str());
        std::string item;
        while (std::getline(s, item, ',')) values.push_back(std::stod(item));
        boxes.push_back(values);
    }
    return boxes;
}

fs::path checkerScript() { return fs::path(AGGRELOD_SOURCE_DIR) / "tests" / "web" / "check_tileset.mjs"; }

RunResult runChecker(const fs::path& tileset, const fs::path& workDir) {
    return runProgram({AGGRELOD_NODE, checkerScript().string(), tileset.string()}, workDir);
}

/// "key=value" from the checker's summary line, or -1.
double summaryValue(const std::string& out, const std::string& key) {
    const std::regex r("\\b" + key + "=([-0-9.e+]+)");
    std::smatch m;
    return std::regex_search(out, m, r) ? std::stod(m[1].str()) : -1;
}

}  // namespace

// glTF (y-up) box [lo, hi] -> 3D Tiles (z-up) box: centre (cx, -cz, cy), half axes (hx,0,0),
// (0,hz,0), (0,0,hy), grown by 1e-6 of the scene diagonal.
TEST(TilesExport, BoxesFollowTheYUpToZUpConvention) {
    HierarchyNodes nodes;
    std::vector<InputObject> objects;
    makeTwoBoxHierarchy(nodes, objects);
    std::string json, error;
    io::TilesetSummary summary;
    ASSERT_TRUE(io::makeTilesetJson(nodes, objects, json, summary, error)) << error;
    EXPECT_EQ(summary.tileCount, 3u);
    EXPECT_EQ(summary.contentCount, 3u);
    const double diagonal = std::sqrt(3.0 * 3.0 + 2.0 * 2.0 + 3.0 * 3.0);
    EXPECT_DOUBLE_EQ(summary.geometricError, diagonal);  // nothing drawn: the scene's diagonal
    const double pad = 1e-6 * diagonal;
    const auto boxes = boxesOf(json);
    ASSERT_EQ(boxes.size(), 3u) << json;
    // Tiles in depth-first order: root (node 2), node 0, node 1.
    const std::vector<std::vector<double>> expected = {
        {1.5, -1.5, 1.0, 1.5 + pad, 0, 0, 0, 1.5 + pad, 0, 0, 0, 1.0 + pad},
        {0.5, -1.5, 1.0, 0.5 + pad, 0, 0, 0, 1.5 + pad, 0, 0, 0, 1.0 + pad},
        {2.5, -0.5, 0.5, 0.5 + pad, 0, 0, 0, 0.5 + pad, 0, 0, 0, 0.5 + pad},
    };
    for (size_t b = 0; b < 3; ++b) {
        ASSERT_EQ(boxes[b].size(), 12u);
        for (size_t i = 0; i < 12; ++i) EXPECT_NEAR(boxes[b][i], expected[b][i], 1e-12) << "box " << b << " value " << i;
    }
    EXPECT_NE(json.find("\"version\": \"1.1\""), std::string::npos);
    EXPECT_NE(json.find("\"geometricError\": 0.5"), std::string::npos) << json;
    io::Json parsed;
    ASSERT_TRUE(io::parseJson(json, parsed, error)) << error;
    const io::Json& right = parsed["root"]["children"][1];  // node 1
    EXPECT_EQ(right["content"]["uri"], "node1.glb") << json;
    EXPECT_EQ(right["extras"]["object"], "right") << json;
    EXPECT_EQ(right["extras"]["id"], 7) << json;
    EXPECT_EQ(json.find("\"refine\": \"ADD\""), std::string::npos);
}

// Several roots and an object the bake left out (no geometry): a content-less root whose
// children are the roots; the left-out object gets no tile.
TEST(TilesExport, SeveralRootsGetAContentlessRoot) {
    HierarchyNodes nodes;
    std::vector<InputObject> objects;
    makeTwoBoxHierarchy(nodes, objects);
    nodes.nodes.pop_back();
    nodes.nodes[0].parent = nodes.nodes[1].parent = kNoNode;
    objects.push_back(samples::makeBox("leftOut", {9, 9, 9}, {10, 10, 10}));
    HierarchyNode leftOut;
    leftOut.leaf = true;
    leftOut.sources = {2};
    nodes.nodes.insert(nodes.nodes.begin() + 2, leftOut);
    nodes.objectCount = 3;
    nodes.roots = {0, 1, 2};
    std::string json, error;
    io::TilesetSummary summary;
    ASSERT_TRUE(io::makeTilesetJson(nodes, objects, json, summary, error)) << error;
    EXPECT_EQ(summary.tileCount, 3u);
    EXPECT_EQ(summary.contentCount, 2u);
    EXPECT_EQ(json.find("node2.glb"), std::string::npos);
    EXPECT_EQ(json.find("leftOut"), std::string::npos);

    nodes.nodes[0].children = {5};  // a child that does not come before its parent
    EXPECT_FALSE(io::makeTilesetJson(nodes, objects, json, summary, error));
    EXPECT_NE(error.find("child 5"), std::string::npos) << error;
}

TEST(TilesExport, BakedSampleTilesetIsValid) {
    AGGRELOD_REQUIRE_VALIDATOR();
    const fs::path dir = freshTestDir(currentTestName());
    const auto objects = samples::makeSpheres15(1);
    std::string error;
    ASSERT_TRUE(io::writeObjectsGlb(objects, (dir / "spheres15.glb").string(), error)) << error;
    for (const char* threads : {"1", "2"}) {
        const fs::path out = dir / (std::string("t") + threads);
        const RunResult r = runProgram({AGGRELOD_CLI, "bake", (dir / "spheres15.glb").string(), "-o", out.string(),
                                        "--tiles", "--levels", "4", "--threads", threads},
                                       dir);
        ASSERT_TRUE(r.exited && r.exitCode == 0) << r.describe();
        EXPECT_NE(r.out.find("tiles/tileset.json"), std::string::npos) << r.describe();
    }
    const fs::path tiles = dir / "t1" / "tiles";
    const RunResult check = runChecker(tiles / "tileset.json", dir);
    EXPECT_TRUE(check.exited && check.exitCode == 0) << check.describe();
    EXPECT_EQ(summaryValue(check.out, "glbErrors"), 0) << check.out;
    // Every original object is one leaf; the hierarchy has proxies above them.
    EXPECT_EQ(summaryValue(check.out, "leaves"), double(objects.size())) << check.out;
    EXPECT_GT(summaryValue(check.out, "contents"), double(objects.size())) << check.out;
    EXPECT_GE(summaryValue(check.out, "depth"), 2) << check.out;
    EXPECT_GT(summaryValue(check.out, "rootError"), 0) << check.out;

    // Same bytes whatever the thread count.
    size_t files = 0;
    for (const auto& entry : fs::directory_iterator(tiles)) {
        const fs::path other = dir / "t2" / "tiles" / entry.path().filename();
        ASSERT_TRUE(fs::exists(other)) << other;
        EXPECT_TRUE(readFile(entry.path()) == readFile(other)) << entry.path().filename() << " differs";
        ++files;
    }
    size_t otherFiles = 0;
    for (const auto& entry : fs::directory_iterator(dir / "t2" / "tiles")) otherFiles += entry.is_regular_file();
    EXPECT_EQ(files, otherFiles);
    EXPECT_EQ(double(files), summaryValue(check.out, "contents") + 1);  // + tileset.json
    EXPECT_FALSE(fs::exists(dir / "t1" / "tiles.tmp"));

    // The checker catches broken tilesets.
    const std::string json = readFile(tiles / "tileset.json");
    struct Breakage {
        std::string from, to, expected;
    };
    const std::vector<Breakage> breakages = {
        {"\"refine\": \"REPLACE\"", "\"refine\": \"ADD\"", "not \"REPLACE\""},
        {"\"geometricError\": 0,", "\"geometricError\": 1e9,", "exceeds its parent's"},
        {"\"version\": \"1.1\"", "\"version\": \"0.9\"", "version"},
    };
    for (const Breakage& b : breakages) {
        const size_t at = json.rfind(b.from);
        ASSERT_NE(at, std::string::npos) << b.from;
        std::string broken = json;
        broken.replace(at, b.from.size(), b.to);
        writeFile(tiles / "broken.json", broken);
        const RunResult r = runChecker(tiles / "broken.json", dir);
        EXPECT_TRUE(r.exited && r.exitCode == 1) << b.to << "\n" << r.describe();
        EXPECT_NE(r.out.find(b.expected), std::string::npos) << b.to << "\n" << r.describe();
    }
    {
        // The last tile (a leaf) moved far away: outside its parent.
        const size_t at = json.rfind("\"box\": [");
        ASSERT_NE(at, std::string::npos);
        const size_t numberStart = at + 8, numberEnd = json.find(',', numberStart);
        std::string broken = json;
        broken.replace(numberStart, numberEnd - numberStart, "1000000");
        writeFile(tiles / "broken.json", broken);
        const RunResult r = runChecker(tiles / "broken.json", dir);
        EXPECT_TRUE(r.exited && r.exitCode == 1) << r.describe();
        EXPECT_NE(r.out.find("not inside its parent"), std::string::npos) << r.describe();
    }
    // ... and a GLB the validator rejects.
    std::string glb = readFile(tiles / "node0.glb");
    glb.resize(glb.size() - 8);  // truncated BIN chunk
    writeFile(tiles / "node0.glb", glb);
    const RunResult r = runChecker(tiles / "tileset.json", dir);
    EXPECT_TRUE(r.exited && r.exitCode == 1) << r.describe();
    EXPECT_GT(summaryValue(r.out, "glbErrors"), 0) << r.describe();
}

// An object with a NaN coordinate is left out of the bake: the tileset skips it and stays valid.
TEST(TilesExport, ObjectLeftOutOfTheBakeHasNoTile) {
    AGGRELOD_REQUIRE_VALIDATOR();
    const fs::path dir = freshTestDir(currentTestName());
    auto objects = samples::makeTwoCubes(0.5);
    InputObject bad = samples::makeBox("broken", {5, 0, 0}, {6, 1, 1});
    bad.positions[4] = std::numeric_limits<double>::quiet_NaN();
    objects.push_back(bad);
    std::string error;
    ASSERT_TRUE(io::writeObjectsGlb(objects, (dir / "scene.glb").string(), error)) << error;
    const RunResult r = runProgram(
        {AGGRELOD_CLI, "bake", (dir / "scene.glb").string(), "-o", (dir / "out").string(), "--tiles", "--delta", "1"}, dir);
    ASSERT_TRUE(r.exited && r.exitCode == 0) << r.describe();
    EXPECT_NE(r.err.find("broken"), std::string::npos) << r.describe();
    const std::string json = readFile(dir / "out" / "tiles" / "tileset.json");
    EXPECT_EQ(json.find("\"broken\""), std::string::npos) << json;
    const RunResult check = runChecker(dir / "out" / "tiles" / "tileset.json", dir);
    EXPECT_TRUE(check.exited && check.exitCode == 0) << check.describe();
    EXPECT_EQ(summaryValue(check.out, "leaves"), 2) << check.out;
}
