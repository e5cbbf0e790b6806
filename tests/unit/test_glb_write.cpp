// SPDX-License-Identifier: AGPL-3.0-or-later
// The GLB writer of the bake (bake/gltf_write.cpp): its JSON text is written by aggrelod
// itself, so names with quotes, control characters, non-ASCII letters and bytes that are not
// UTF-8 must come out as valid glTF and read back; numbers must keep their type.
#include "runtime_export.h"
#include "scene_io.h"
#include "test_support.h"
#include "tiles_export.h"

#include <aggrelod/hierarchy_nodes.h>
#include <aggrelod/samples.h>

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>

namespace aggrelod {
namespace {

using namespace aggrelod::testing;

std::string glbJson(const fs::path& file) {
    std::ifstream in(file, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_GE(bytes.size(), 20u);
    if (bytes.size() < 20) return {};
    uint32_t total = 0, jsonLength = 0;
    std::memcpy(&total, bytes.data() + 8, 4);
    std::memcpy(&jsonLength, bytes.data() + 12, 4);
    EXPECT_EQ(total, bytes.size());
    EXPECT_EQ(bytes.compare(16, 4, "JSON"), 0);
    EXPECT_EQ(jsonLength % 4, 0u);
    return bytes.substr(20, jsonLength);
}

TEST(GlbWrite, AwkwardNamesAreEscapedAndReadBack) {
    const fs::path dir = freshTestDir(currentTestName());
    std::vector<InputObject> objects = samples::makeTwoCubes(0.5);
    ASSERT_EQ(objects.size(), 2u);
    objects.push_back(objects[1]);
    objects.push_back(objects[1]);
    for (size_t i = 2; i < objects.size(); ++i)
        for (size_t v = 0; v < objects[i].positions.size(); v += 3) objects[i].positions[v] += 3.0 * double(i);
    objects[0].name = "quote\" back\\slash /";
    objects[1].name = std::string("line\nbreak\ttab\x01");
    objects[2].name = "na\xC3\xAFve \xE2\x9C\x93";  // naïve ✓
    objects[3].name = "bad\xFF\xFE" "end";               // not UTF-8
    std::string error;
    ASSERT_TRUE(io::writeObjectsGlb(objects, (dir / "names.glb").string(), error)) << error;
    validateGltf({dir / "names.glb"}, dir);
    const std::string json = glbJson(dir / "names.glb");
    EXPECT_NE(json.find("quote\\\" back\\\\slash /"), std::string::npos) << json.substr(0, 400);
    EXPECT_NE(json.find("line\\nbreak\\ttab\\u0001"), std::string::npos) << json.substr(0, 400);
    io::SceneReadResult back;
    ASSERT_TRUE(io::readGltfScene((dir / "names.glb").string(), {}, back, error)) << error;
    ASSERT_EQ(back.objects.size(), 4u);
    EXPECT_EQ(back.objects[0].name, objects[0].name);
    EXPECT_EQ(back.objects[1].name, objects[1].name);
    EXPECT_EQ(back.objects[2].name, objects[2].name);
    EXPECT_EQ(back.objects[3].name, "bad\xEF\xBF\xBD\xEF\xBF\xBD" "end");  // U+FFFD per stray byte
    for (size_t i = 0; i < 4; ++i) {
        EXPECT_EQ(back.objects[i].indices, objects[i].indices) << i;
        ASSERT_EQ(back.objects[i].positions.size(), objects[i].positions.size()) << i;
        for (size_t k = 0; k < objects[i].positions.size(); ++k)
            EXPECT_EQ(back.objects[i].positions[k], double(float(objects[i].positions[k]))) << i << " " << k;
    }
}

std::string fileBytes(const fs::path& file) {
    std::ifstream in(file, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// The bake moves the nodes' meshes to a spill file before it writes (spillNodeMeshes): every
// writer must read them back and give the files it gives from the nodes in memory, byte for
// byte; the spill file goes with the last nodes using it; a spill file damaged under the
// bake is an error naming it, never a crash.
TEST(GlbWrite, SpilledNodeMeshesGiveTheSameFiles) {
    const fs::path dir = freshTestDir(currentTestName());
    std::vector<InputObject> objects;
    for (int i = 0; i < 6; ++i) {
        const double x = 1.6 * i;
        objects.push_back(i % 2 ? samples::makeUvSphere("ball" + std::to_string(i), {x + 0.5, 0.5, 0.5}, 0.5, 12, 8)
                                : samples::makeBox("box" + std::to_string(i), {x, 0, 0}, {x + 1, 1, 1 + 0.2 * i}));
        if (i % 3 != 2)  // colours on some objects only
            for (size_t t = 0; t < objects.back().indices.size() / 3; ++t)
                objects.back().triangleColors.insert(objects.back().triangleColors.end(), {0.1f * float(i), 0.5f, 0.2f, 1.0f});
    }
    Settings3D settings;
    settings.deltas = {0.3, 0.8, 3.0};
    settings.threadCount = 1;
    Hierarchy3D h;
    ASSERT_TRUE(buildHierarchy3D(objects, settings, h));
    HierarchyNodes nodes;
    ProxySettings proxySettings;
    proxySettings.threadCount = 1;
    std::string error;
    ASSERT_TRUE(buildHierarchyNodes(h, objects, proxySettings, nodes, error)) << error;
    ASSERT_GT(nodes.nodes.size(), objects.size() + 3);

    const fs::path spillPath = dir / "meshes.spill";
    auto spilled = std::make_unique<HierarchyNodes>(nodes);
    ASSERT_TRUE(spillNodeMeshes(*spilled, objects, spillPath.string(), error)) << error;
    ASSERT_TRUE(fs::exists(spillPath));
    size_t inFile = 0;
    for (uint32_t i = 0; i < nodes.nodes.size(); ++i) {
        const HierarchyNode& before = nodes.nodes[i];
        const HierarchyNode& after = spilled->nodes[i];
        EXPECT_TRUE(after.positions.empty() && after.indices.empty() && after.faceColors.empty()) << i;
        EXPECT_EQ(nodeTriangleCount(after), before.indices.size() / 3) << i;
        EXPECT_EQ(after.meshPlace.kind, before.indices.empty() ? NodeMeshPlace::Kind::InNode
                                        : before.leaf          ? NodeMeshPlace::Kind::Object
                                                               : NodeMeshPlace::Kind::File)
            << i;
        inFile += after.meshPlace.kind == NodeMeshPlace::Kind::File;
        NodeMesh back;
        ASSERT_TRUE(readNodeMesh(*spilled, objects, i, back, error)) << error;
        EXPECT_EQ(back.positions, before.positions) << i;
        EXPECT_EQ(back.indices, before.indices) << i;
        EXPECT_EQ(back.faceColors, before.faceColors) << i;
    }
    EXPECT_GT(inFile, 3u);

    // The proxies stage spilling as it goes (leaves by reference or copied, each mesh to a
    // spill file once nothing in the stage needs it, from one thread or from two at once):
    // the same nodes, every mesh out of memory and read back the same.
    HierarchyNodes built;
    for (const bool byReference : {false, true}) {
        built = HierarchyNodes{};
        ProxySettings spilling = proxySettings;
        spilling.leavesByReference = byReference;
        spilling.threadCount = byReference ? 2 : 1;
        spilling.meshSpillPath = (dir / "built.spill").string();
        bool released = false;
        spilling.releaseFreedMemory = [&] { released = true; };
        ASSERT_TRUE(buildHierarchyNodes(h, objects, spilling, built, error)) << error;
        EXPECT_TRUE(released);
        ASSERT_TRUE(fs::exists(dir / "built.spill"));
        ASSERT_EQ(built.nodes.size(), nodes.nodes.size());
        EXPECT_EQ(built.roots, nodes.roots);
        for (uint32_t i = 0; i < nodes.nodes.size(); ++i) {
            const HierarchyNode& a = nodes.nodes[i];
            const HierarchyNode& b = built.nodes[i];
            EXPECT_TRUE(b.positions.empty() && b.indices.empty() && b.faceColors.empty()) << i;
            EXPECT_EQ(b.meshPlace.kind, a.indices.empty() ? NodeMeshPlace::Kind::InNode
                                        : a.leaf          ? NodeMeshPlace::Kind::Object
                                                          : NodeMeshPlace::Kind::File)
                << i;
            EXPECT_EQ(b.parent, a.parent) << i;
            EXPECT_EQ(b.children, a.children) << i;
            EXPECT_EQ(b.sources, a.sources) << i;
            EXPECT_EQ(b.geometricError, a.geometricError) << i;
            EXPECT_EQ(b.sphereRadius, a.sphereRadius) << i;
            for (int k = 0; k < 3; ++k) {
                EXPECT_EQ(b.boundsMin[k], a.boundsMin[k]) << i;
                EXPECT_EQ(b.boundsMax[k], a.boundsMax[k]) << i;
                EXPECT_EQ(b.sphereCenter[k], a.sphereCenter[k]) << i;
            }
            NodeMesh back;
            ASSERT_TRUE(readNodeMesh(built, objects, i, back, error)) << error;
            EXPECT_EQ(back.positions, a.positions) << i;
            EXPECT_EQ(back.indices, a.indices) << i;
            EXPECT_EQ(back.faceColors, a.faceColors) << i;
        }
    }
    // Nothing left for spillNodeMeshes to move: no second file.
    ASSERT_TRUE(spillNodeMeshes(built, objects, (dir / "second.spill").string(), error)) << error;
    EXPECT_FALSE(fs::exists(dir / "second.spill"));

    // Every writer, from the nodes in memory and from the spilled ones.
    for (const char* which : {"memory", "spilled", "built"}) {
        const HierarchyNodes& n = std::string(which) == "memory" ? nodes : std::string(which) == "built" ? built : *spilled;
        const fs::path out = dir / which;
        fs::create_directories(out / "tiles");
        ASSERT_TRUE(io::writeLevelsGlb(h, objects, (out / "levels.glb").string(), error, &n, 2)) << error;
        ASSERT_TRUE(io::writeProxiesGlb(n, objects, (out / "proxies.glb").string(), error, 2)) << error;
        ASSERT_TRUE(io::writeRuntimeScene(n, objects, 5, "test", (out / "scene.aglod").string(), error, 2)) << error;
        io::TilesetSummary summary;
        ASSERT_TRUE(io::writeTileset(n, objects, (out / "tiles").string(), summary, error)) << error;
    }
    for (const char* file : {"levels.glb", "proxies.glb", "scene.aglod", "tiles/tileset.json"}) {
        EXPECT_EQ(fileBytes(dir / "memory" / file), fileBytes(dir / "spilled" / file)) << file;
        EXPECT_EQ(fileBytes(dir / "memory" / file), fileBytes(dir / "built" / file)) << file;
    }
    size_t tileFiles = 0;
    for (const auto& e : fs::directory_iterator(dir / "memory" / "tiles")) {
        ++tileFiles;
        EXPECT_EQ(fileBytes(e.path()), fileBytes(dir / "spilled" / "tiles" / e.path().filename())) << e.path();
    }
    EXPECT_GT(tileFiles, 3u);

    // Damaged under the bake: an error naming the file.
    fs::resize_file(spillPath, fs::file_size(spillPath) / 2);
    NodeMesh back;
    uint32_t last = 0;
    for (uint32_t i = 0; i < spilled->nodes.size(); ++i)
        if (spilled->nodes[i].meshPlace.kind == NodeMeshPlace::Kind::File) last = i;
    EXPECT_FALSE(readNodeMesh(*spilled, objects, last, back, error));
    EXPECT_NE(error.find(spillPath.string()), std::string::npos) << error;
    EXPECT_FALSE(io::writeProxiesGlb(*spilled, objects, (dir / "damaged.glb").string(), error, 2));
    EXPECT_NE(error.find(spillPath.string()), std::string::npos) << error;
    EXPECT_FALSE(io::writeRuntimeScene(*spilled, objects, 5, "test", (dir / "damaged.aglod").string(), error, 2));
    EXPECT_NE(error.find(spillPath.string()), std::string::npos) << error;
    EXPECT_FALSE(fs::exists(dir / "damaged.aglod"));
    fs::create_directories(dir / "damaged-tiles");
    io::TilesetSummary damagedSummary;
    EXPECT_FALSE(io::writeTileset(*spilled, objects, (dir / "damaged-tiles").string(), damagedSummary, error));
    EXPECT_NE(error.find(spillPath.string()), std::string::npos) << error;
    // A spill file is never written over, even by mistake.
    HierarchyNodes again = nodes;
    EXPECT_FALSE(spillNodeMeshes(again, objects, spillPath.string(), error));
    EXPECT_NE(error.find("already exists"), std::string::npos) << error;

    // The spill file goes with the last nodes sharing it.
    HierarchyNodes copy = *spilled;
    spilled.reset();
    EXPECT_TRUE(fs::exists(spillPath));
    copy = HierarchyNodes{};
    EXPECT_FALSE(fs::exists(spillPath));
    built = HierarchyNodes{};
    EXPECT_FALSE(fs::exists(dir / "built.spill"));
}

// levels.glb and proxies.glb list every object of every node by name: on a large world their
// JSON runs to hundreds of megabytes, which the writer streams through a temporary file in
// blocks of 1 MiB. A JSON chunk of several blocks must come out whole, valid and in order,
// and no temporary file may stay behind.
TEST(GlbWrite, JsonOfSeveralBlocksIsWholeAndLeavesNoTemporaryFile) {
    const fs::path dir = freshTestDir(currentTestName());
    std::vector<InputObject> objects;
    for (int i = 0; i < 40; ++i) {
        const double x = 1.5 * i;  // unit boxes 0.5 apart
        objects.push_back(samples::makeBox("box" + std::to_string(100 + i) + "_" + std::string(30000, char('a' + i % 26)),
                                           {x, 0, 0}, {x + 1, 1, 1}));
    }
    Settings3D settings;
    settings.deltas = {0.25, 1.0};
    settings.threadCount = 1;
    Hierarchy3D h;
    ASSERT_TRUE(buildHierarchy3D(objects, settings, h));
    ASSERT_EQ(h.levels.size(), 2u);
    ASSERT_EQ(h.levels[1].aggregates.size(), 1u);
    HierarchyNodes nodes;
    ProxySettings proxySettings;
    proxySettings.threadCount = 1;
    std::string error;
    ASSERT_TRUE(buildHierarchyNodes(h, objects, proxySettings, nodes, error)) << error;
    const fs::path levels = dir / "levels.glb", proxies = dir / "proxies.glb";
    ASSERT_TRUE(io::writeLevelsGlb(h, objects, levels.string(), error, &nodes, 2)) << error;
    ASSERT_TRUE(io::writeProxiesGlb(nodes, objects, proxies.string(), error, 2)) << error;
    for (const fs::path& file : {levels, proxies}) {
        const std::string json = glbJson(file);
        EXPECT_GT(json.size(), size_t(2) << 20) << file << ": the JSON must span several blocks";
        // Every object is named once per level in levels.glb, and at least in its leaf and in
        // the group of all 40 in proxies.glb; the last one too, at the end of the last block.
        for (const InputObject& o : {objects.front(), objects.back()}) {
            size_t count = 0;
            for (size_t at = json.find(o.name); at != std::string::npos; at = json.find(o.name, at + 1)) ++count;
            EXPECT_GE(count, 2u) << file << ": " << o.name.substr(0, 8);
        }
    }
    validateGltf({levels, proxies}, dir);
    std::vector<io::LevelsGlbNode> levelNodes;
    ASSERT_TRUE(io::readLevelsGlb(levels.string(), levelNodes, error)) << error;
    ASSERT_EQ(levelNodes.size(), 41u);
    EXPECT_EQ(levelNodes.back().sourceCount, 40u);
    std::vector<io::ProxiesGlbNode> proxyNodes;
    ASSERT_TRUE(io::readProxiesGlb(proxies.string(), proxyNodes, error)) << error;
    size_t leaves = 0;
    for (const io::ProxiesGlbNode& n : proxyNodes) leaves += n.leaf;
    EXPECT_EQ(leaves, 40u);
    for (const auto& entry : fs::directory_iterator(dir)) {
        const std::string name = entry.path().filename().string();
        EXPECT_EQ(name.find("-part"), std::string::npos) << name << ": a temporary file left behind";
    }
}

}  // namespace
}  // namespace aggrelod
