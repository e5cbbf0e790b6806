// SPDX-License-Identifier: AGPL-3.0-or-later
// The open-world generator (samples/include/aggrelod/world.h): deterministic, closed meshes,
// nothing touching, blocks independent of the world's size, and a streamed GLB that the
// validator accepts and the bake's reader reads back as generated.
#include "scene_io.h"
#include "generated_world.h"
#include "test_support.h"

#include <aggrelod/aggregate3d.h>
#include <aggrelod/samples.h>
#include <aggrelod/world.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <map>
#include <string>
#include <vector>

using namespace aggrelod;
using namespace aggrelod::testing;

namespace {

std::vector<InputObject> world(uint64_t count, uint32_t seed = 1) { return aggrelod::testing::generatedWorld(count, seed); }

/// The part of an object's name after the block prefix "bRRRR_CCCC_".
std::string kindOf(const std::string& name) {
    const size_t first = name.find('_'), second = name.find('_', first + 1);
    const size_t end = name.find('_', second + 1);
    return name.substr(second + 1, end == std::string::npos ? std::string::npos : end - second - 1);
}

}  // namespace

TEST(SamplesWorld, ObjectsAreClosedNumberedAndDeterministic) {
    const std::vector<InputObject> a = world(3000), b = world(3000);
    ASSERT_EQ(a.size(), 3000u);
    std::map<std::string, size_t> kinds;
    size_t triangles = 0;
    for (size_t i = 0; i < a.size(); ++i) {
        EXPECT_EQ(a[i].id, i);
        EXPECT_EQ(samples::checkClosedMesh(a[i]), "") << a[i].name;
        EXPECT_GT(samples::signedVolume(a[i]), 0) << a[i].name;
        EXPECT_EQ(a[i].positions, b[i].positions) << a[i].name;
        EXPECT_EQ(a[i].indices, b[i].indices) << a[i].name;
        EXPECT_EQ(a[i].name, b[i].name);
        ++kinds[kindOf(a[i].name)];
        triangles += a[i].indices.size() / 3;
    }
    for (const char* kind : {"terrain", "road", "tree", "house", "barrel", "rock", "hay"})
        EXPECT_GT(kinds[kind], 0u) << "no " << kind << " in 3000 objects";
    const double mean = double(triangles) / double(a.size());
    EXPECT_GT(mean, 100);
    EXPECT_LT(mean, 200);
    // Another seed, another world.
    const std::vector<InputObject> c = world(3000, 2);
    size_t same = 0;
    for (size_t i = 0; i < c.size(); ++i) same += c[i].positions == a[i].positions ? 1 : 0;
    EXPECT_LT(same, 100u);
}

TEST(SamplesWorld, ABlockIsTheSameInEveryWorldThatHasIt) {
    // Both worlds lay their blocks out in rows of a different length; the block at row 0,
    // column 0 (the first objects) and every other block they share must be identical.
    std::map<std::string, const InputObject*> small;
    const std::vector<InputObject> a = world(400), b = world(6000);
    for (const InputObject& o : a) small[o.name] = &o;
    size_t shared = 0;
    for (const InputObject& o : b) {
        const auto it = small.find(o.name);
        if (it == small.end()) continue;
        ++shared;
        EXPECT_EQ(it->second->positions, o.positions) << o.name;
        EXPECT_EQ(it->second->indices, o.indices) << o.name;
    }
    EXPECT_GT(shared, 300u);
}

TEST(SamplesWorld, RefusesCountsOutOfRange) {
    samples::WorldSettings settings;
    settings.objectCount = 0;
    EXPECT_THROW(samples::generateWorld(settings, [](InputObject&) {}), std::invalid_argument);
    settings.objectCount = samples::kMaxWorldObjects + 1;
    EXPECT_THROW(samples::generateWorld(settings, [](InputObject&) {}), std::invalid_argument);
}

TEST(WorldCli, StreamedGlbIsValidIdenticalAndReadsBack) {
    const fs::path dir = freshTestDir(currentTestName());
    const std::string file = (dir / "world.glb").string(), again = (dir / "again.glb").string();
    for (const std::string& out : {file, again}) {
        const RunResult r = runProgram({AGGRELOD_MAKE_SAMPLE, "world", "--objects", "1500", "--seed", "3", "-o", out}, dir);
        ASSERT_TRUE(r.exited && r.exitCode == 0) << r.describe();
        EXPECT_NE(r.out.find("world: 1500 objects"), std::string::npos) << r.describe();
    }
    EXPECT_EQ(readFile(file), readFile(again));
    validateGltf({file}, dir);

    io::SceneReadOptions options;
    io::SceneReadResult read;
    std::string error;
    ASSERT_TRUE(io::readGltfScene(file, options, read, error)) << error;
    const std::vector<InputObject> generated = world(1500, 3);
    ASSERT_EQ(read.objects.size(), generated.size());
    for (size_t i = 0; i < generated.size(); ++i) {
        const InputObject& r = read.objects[i];
        const InputObject& g = generated[i];
        ASSERT_EQ(r.name, g.name);
        ASSERT_EQ(r.indices.size(), g.indices.size()) << g.name;
        ASSERT_EQ(r.positions.size(), g.positions.size()) << g.name;
        for (size_t k = 0; k < g.positions.size(); ++k)
            ASSERT_EQ(r.positions[k], double(float(g.positions[k]))) << g.name;  // float32 in the file
    }
}

TEST(WorldCli, NothingTouchesInABakedCorner) {
    // Two blocks' worth: every object stays its own model (no touching or overlapping pair is
    // merged) and the bake reports no problem with any of them.
    const std::vector<InputObject> objects = world(60);
    Settings3D settings;
    settings.automaticLevelCount = 2;
    settings.threadCount = 2;
    Hierarchy3D h;
    ASSERT_TRUE(buildHierarchy3D(objects, settings, h));
    EXPECT_EQ(h.modelCount, objects.size());
    for (const Diagnostic& d : h.diagnostics) EXPECT_NE(d.severity, Diagnostic::Severity::Warning) << d.object << ": " << d.message;
}
