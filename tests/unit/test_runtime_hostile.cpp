// SPDX-License-Identifier: AGPL-3.0-or-later
// Hostile runtime input: forged `.aglod` files whose checksum is valid (trailing bytes,
// shared ranges, levels out of order, coordinates Embree cannot take), out-of-range float
// arguments to the C API, and a valid but very deep tree through `aggrelod inspect`.
#include <aggrelod/runtime_build.h>
#include <aggrelod/runtime_file.h>
#include <aggrelod_runtime.h>

#include "../../runtime/src/aglod_layout.h"
#include "synthetic_hierarchy.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <string>
#include <vector>

using namespace aggrelod::runtime;
using aggrelod::testing::makeSyntheticHierarchy;
namespace at = aggrelod::testing;

namespace {

std::vector<uint8_t> writeOrDie(const BuildArrays& p) {
    std::vector<uint8_t> bytes;
    std::string error;
    EXPECT_TRUE(writeRuntimeFile(p, bytes, error)) << error;
    return bytes;
}

/// Opens an exact heap copy (16-byte aligned, as the reader requires).
FileStatus openCopy(const std::vector<uint8_t>& bytes, std::string& message) {
    std::unique_ptr<uint8_t[]> copy(new uint8_t[bytes.size() + 16]);
    uint8_t* aligned = copy.get() + (16 - reinterpret_cast<uintptr_t>(copy.get()) % 16) % 16;
    std::memcpy(aligned, bytes.data(), bytes.size());
    RuntimeFile file;
    return RuntimeFile::openMemory(aligned, bytes.size(), file, message);
}

void resign(std::vector<uint8_t>& bytes) {
    using namespace aggrelod::runtime::layout;
    const uint64_t total = loadU64(bytes.data() + 16);
    const uint64_t sum = fileChecksum(bytes.data(), size_t(total), kChecksumOffset);
    std::memcpy(bytes.data() + kChecksumOffset, &sum, 8);
}

/// The node records in the file (section 1), patched in place.
NodeRecord* nodesOf(std::vector<uint8_t>& bytes, uint64_t& count) {
    uint64_t offset = 0;
    std::memcpy(&offset, bytes.data() + 64 + 8, 8);
    std::memcpy(&count, bytes.data() + 64 + 16, 8);
    return reinterpret_cast<NodeRecord*>(bytes.data() + offset);
}

/// A valid chain: one leaf under `depth - 1` per-object LOD nodes, each with one child;
/// every node has its own source entry.
BuildArrays makeChain(uint32_t depth) {
    BuildArrays p;
    p.objectNames = {"deep"};
    p.nodes.resize(depth);
    const float lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
    for (uint32_t k = 0; k < depth; ++k) {
        NodeRecord& n = p.nodes[k];
        n.firstSource = uint32_t(p.sourceObjects.size());
        n.sourceCount = 1;
        p.sourceObjects.push_back(0);
        if (k == 0) {
            n.level = kLeafLevel;
            at::appendBoxMesh(p, n, lo, hi);
        } else {
            n.level = kObjectLodLevel;
            n.firstChild = uint32_t(p.childIndices.size());
            n.childCount = 1;
            p.childIndices.push_back(k - 1);
            n.geometricError = 0.5f;
        }
        if (k + 1 < depth) n.parent = k + 1;
        for (int c = 0; c < 3; ++c) {
            n.boundsMin[c] = lo[c];
            n.boundsMax[c] = hi[c];
            n.sphereCenter[c] = 0.5f;
        }
        n.sphereRadius = 0.8661f;
    }
    p.toolVersion = "test";
    return p;
}

}  // namespace

TEST(RuntimeHostile, TrailingBytesAreRefused) {
    std::vector<uint8_t> bytes = writeOrDie(makeSyntheticHierarchy(40, 3));
    std::string message;
    ASSERT_EQ(openCopy(bytes, message), FileStatus::Ok) << message;
    bytes.resize(bytes.size() + 32, 0);
    EXPECT_EQ(openCopy(bytes, message), FileStatus::BadSection);
    EXPECT_NE(message.find("after the declared end"), std::string::npos) << message;
}

TEST(RuntimeHostile, SharedVertexAndIndexRangesAreRefused) {
    const std::vector<uint8_t> good = writeOrDie(makeSyntheticHierarchy(40, 3));
    std::vector<uint8_t> bytes = good;
    uint64_t count = 0;
    NodeRecord* nodes = nodesOf(bytes, count);
    // Give every node the mesh of the largest one: all ranges valid, all shared.
    uint32_t biggest = 0;
    for (uint32_t i = 0; i < count; ++i)
        if (nodes[i].indexCount > nodes[biggest].indexCount) biggest = i;
    for (uint32_t i = 0; i < count; ++i) {
        nodes[i].firstVertex = nodes[biggest].firstVertex;
        nodes[i].vertexCount = nodes[biggest].vertexCount;
        nodes[i].firstIndex = nodes[biggest].firstIndex;
        nodes[i].indexCount = nodes[biggest].indexCount;
    }
    resign(bytes);
    std::string message;
    EXPECT_EQ(openCopy(bytes, message), FileStatus::BadValue);
    EXPECT_NE(message.find("share"), std::string::npos) << message;

    // Overlapping (not equal) index ranges of two nodes.
    bytes = good;
    nodes = nodesOf(bytes, count);
    uint32_t a = count, b = count;
    for (uint32_t i = 0; i < count && b == count; ++i)
        if (nodes[i].indexCount >= 6) (a == count ? a : b) = i;
    ASSERT_LT(b, count);
    nodes[b].firstIndex = nodes[a].firstIndex + 3;
    nodes[b].indexCount = 3;
    resign(bytes);
    EXPECT_EQ(openCopy(bytes, message), FileStatus::BadValue) << message;
}

TEST(RuntimeHostile, SharedRangesCostLinearTime) {
    // The forgery of the report: many nodes sharing one large index range. Refused quickly.
    BuildArrays p = makeSyntheticHierarchy(2000, 5);
    std::vector<uint8_t> bytes = writeOrDie(p);
    uint64_t count = 0;
    NodeRecord* nodes = nodesOf(bytes, count);
    for (uint32_t i = 1; i < count; ++i) {
        nodes[i].firstIndex = nodes[0].firstIndex;
        nodes[i].indexCount = nodes[0].indexCount;
        nodes[i].firstVertex = nodes[0].firstVertex;
        nodes[i].vertexCount = nodes[0].vertexCount;
    }
    resign(bytes);
    std::string message;
    const auto start = std::chrono::steady_clock::now();
    EXPECT_NE(openCopy(bytes, message), FileStatus::Ok);
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 5.0);
}

TEST(RuntimeHostile, ChildLevelMustBeBelowItsParents) {
    // Chains of per-object LODs are the one exception.
    std::string chainMessage;
    EXPECT_EQ(openCopy(writeOrDie(makeChain(5)), chainMessage), FileStatus::Ok) << chainMessage;
    const BuildArrays p = makeSyntheticHierarchy(60, 4);
    std::vector<uint8_t> bytes = writeOrDie(p);
    uint64_t count = 0;
    NodeRecord* nodes = nodesOf(bytes, count);
    // An aggregate whose parent is an aggregate: give it its parent's level.
    uint32_t child = uint32_t(count);
    for (uint32_t i = 0; i < count; ++i)
        if (nodes[i].childCount > 0 && nodes[i].parent != kNoIndex && nodes[i].level < kMaxAggregateLevel) child = i;
    ASSERT_LT(child, count);
    nodes[child].level = nodes[nodes[child].parent].level;
    resign(bytes);
    std::string message;
    EXPECT_EQ(openCopy(bytes, message), FileStatus::BadTree);
    EXPECT_NE(message.find("is not below its parent"), std::string::npos) << message;
}

TEST(RuntimeHostile, CoordinatesBeyondWhatRaysTakeAreRefused) {
    std::vector<uint8_t> bytes = writeOrDie(makeSyntheticHierarchy(30, 2));
    uint64_t count = 0;
    NodeRecord* nodes = nodesOf(bytes, count);
    for (uint32_t i = 0; i < count; ++i) {
        if (nodes[i].parent != kNoIndex) continue;
        for (int k = 0; k < 3; ++k) {
            nodes[i].boundsMin[k] = -3.4e38f;
            nodes[i].boundsMax[k] = 3.4e38f;
        }
    }
    resign(bytes);
    std::string message;
    EXPECT_EQ(openCopy(bytes, message), FileStatus::BadValue);
    EXPECT_NE(message.find("beyond 1e18"), std::string::npos) << message;
}

TEST(RuntimeHostile, CApiRefusesNonFiniteAndHugeFloats) {
    const std::vector<uint8_t> bytes = writeOrDie(makeSyntheticHierarchy(30, 2));
    std::unique_ptr<uint8_t[]> copy(new uint8_t[bytes.size() + 16]);
    uint8_t* aligned = copy.get() + (16 - reinterpret_cast<uintptr_t>(copy.get()) % 16) % 16;
    std::memcpy(aligned, bytes.data(), bytes.size());
    aglod_file* file = nullptr;
    ASSERT_EQ(aglod_open_memory(aligned, bytes.size(), &file), AGLOD_OK) << aglod_last_error();
    const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
    const float bad[] = {inf, -inf, nan, 1e19f, -2e18f, 3.4e38f};

    aglod_selector* selector = aglod_selector_create(file);
    ASSERT_TRUE(selector);
    aglod_cut cut{};
    for (float v : bad) {
        aglod_camera camera = {{0, 0, v}, 1.0f, 1080.0f};
        EXPECT_EQ(aglod_select(selector, &camera, 1.0f, 0.5f, &cut), AGLOD_INVALID_ARGUMENT) << v;
        camera = {{0, 0, 100}, 1.0f, 1080.0f};
        EXPECT_EQ(aglod_select(selector, &camera, v, 0.5f, &cut), v > 0 && std::isfinite(v)
                                                                          ? AGLOD_OK
                                                                          : AGLOD_INVALID_ARGUMENT)
            << v;
        aglod_view_camera view = {{0, 0, 100}, 1.0f, 1080.0f, {0, 0, -1}, {0, 1, 0}, 1.5f, 0.1f, 0.0f};
        view.forward[0] = v;
        EXPECT_EQ(aglod_select_view(selector, &view, 1.0f, 0.5f, &cut), AGLOD_INVALID_ARGUMENT) << v;
        view.forward[0] = 0;
        view.position[1] = v;
        EXPECT_EQ(aglod_select_view(selector, &view, 1.0f, 0.5f, &cut), AGLOD_INVALID_ARGUMENT) << v;
    }
    aglod_camera camera = {{0, 0, 100}, 1.0f, inf};
    EXPECT_EQ(aglod_select(selector, &camera, 1.0f, 0.5f, &cut), AGLOD_INVALID_ARGUMENT);
    aglod_selector_destroy(selector);

#ifdef AGGRELOD_HAVE_COLLISION
    aglod_collision* collision = aglod_collision_create(file);
    ASSERT_TRUE(collision) << aglod_last_error();
    aglod_hit hit{};
    const float down[3] = {0, 0, -1}, above[3] = {5, 5, 1000};
    for (float v : bad) {
        const float origin[3] = {v, 0, 100};
        EXPECT_EQ(aglod_raycast(collision, origin, down, inf, &hit), 0) << v;
        EXPECT_NE(std::string(aglod_last_error()).find("aglod_raycast"), std::string::npos) << v;
        EXPECT_EQ(aglod_occluded(collision, origin, down, inf), 0) << v;
        EXPECT_NE(std::string(aglod_last_error()).find("aglod_occluded"), std::string::npos) << v;
        const float direction[3] = {0, v, -1};
        EXPECT_EQ(aglod_raycast(collision, above, direction, 10.0f, &hit), 0) << v;
        EXPECT_EQ(aglod_collision_use_distance_cut(collision, origin, 0.01f), AGLOD_INVALID_ARGUMENT) << v;
    }
    EXPECT_EQ(aglod_raycast(collision, above, down, nan, &hit), 0);
    const float zero[3] = {0, 0, 0};
    EXPECT_EQ(aglod_raycast(collision, above, zero, 10.0f, &hit), 0);
    EXPECT_NE(std::string(aglod_last_error()).find("zero"), std::string::npos);
    // Valid rays still work after refused ones (the synthetic city lies in z >= 0 under `above`).
    EXPECT_EQ(aglod_collision_use_level(collision, AGLOD_LEAF_LEVEL), AGLOD_OK);
    int hits = 0;
    for (int x = 0; x < 50; x += 5)
        for (int y = 0; y < 50; y += 5) {
            const float o[3] = {float(x) + 2.5f, float(y) + 2.5f, 1000};
            hits += aglod_raycast(collision, o, down, inf, &hit);
        }
    EXPECT_GT(hits, 0);
    aglod_collision_destroy(collision);
#endif
    aglod_close(file);
}

TEST(RuntimeHostile, InspectPrintsAVeryDeepTreeWithoutRecursion) {
    const uint32_t depth = 200000;
    const std::vector<uint8_t> bytes = writeOrDie(makeChain(depth));
    std::string message;
    ASSERT_EQ(openCopy(bytes, message), FileStatus::Ok) << message;
    const at::fs::path dir = at::freshTestDir(at::currentTestName());
    at::writeFile(dir / "deep.aglod", std::string(bytes.begin(), bytes.end()));
    const at::RunResult r = at::runProgram({AGGRELOD_CLI, "inspect", (dir / "deep.aglod").string()}, dir);
    ASSERT_TRUE(r.exited) << r.describe().substr(0, 2000);
    EXPECT_EQ(r.exitCode, 0) << r.err;
    size_t lines = 0;
    for (char c : r.out) lines += c == '\n';
    EXPECT_GE(lines, size_t(depth));
    // Indentation is capped: the output grows linearly with the node count.
    EXPECT_LT(r.out.size(), size_t(depth) * 400) << "output of " << r.out.size() << " bytes";
    EXPECT_NE(r.out.find("(depth 199999)"), std::string::npos);
}
