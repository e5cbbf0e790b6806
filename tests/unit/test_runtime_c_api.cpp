// The C API (aggrelod_runtime.h): open/close, statuses and messages, selection views,
// raycast, and NULL-safety of every entry point.
#include <aggrelod_runtime.h>

#include <aggrelod/runtime_build.h>
#include <aggrelod/runtime_file.h>
#include <aggrelod/selection.h>

#include "synthetic_hierarchy.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <string>

using aggrelod::testing::makeSyntheticHierarchy;

namespace {
std::vector<uint8_t> syntheticBytes(uint32_t objects) {
    std::vector<uint8_t> bytes;
    std::string error;
    EXPECT_TRUE(aggrelod::runtime::writeRuntimeFile(makeSyntheticHierarchy(objects, 9), bytes, error)) << error;
    return bytes;
}
}  // namespace

TEST(RuntimeCApi, OpenSelectAndNames) {
    const std::vector<uint8_t> bytes = syntheticBytes(300);
    aglod_file* file = nullptr;
    ASSERT_EQ(aglod_open_memory(bytes.data(), bytes.size(), &file), AGLOD_OK) << aglod_last_error();
    EXPECT_EQ(aglod_object_count(file), 300u);
    char name[8];
    EXPECT_EQ(aglod_object_name(file, 123, name, sizeof name), 6u);
    EXPECT_STREQ(name, "box123");
    EXPECT_EQ(aglod_object_name(file, 123, name, 4), 6u);  // truncated, still NUL-terminated
    EXPECT_STREQ(name, "box");
    EXPECT_EQ(aglod_object_name(file, 300, name, sizeof name), 0u);
    EXPECT_EQ(aglod_node_level(file, 0), AGLOD_LEAF_LEVEL);
    EXPECT_EQ(aglod_node_level(file, 1u << 30), AGLOD_NO_INDEX);

    aglod_selector* selector = aglod_selector_create(file);
    ASSERT_NE(selector, nullptr);
    float lo[3], hi[3];
    ASSERT_EQ(aglod_scene_bounds(file, lo, hi), 1);
    aglod_camera camera = {{0.5f * (lo[0] + hi[0]), 50.0f, lo[2] - 6000.0f}, 1.0f, 1080.0f};
    aglod_cut cut;
    ASSERT_EQ(aglod_select(selector, &camera, 4.0f, 0.75f, &cut), AGLOD_OK);
    // Same cut as the C++ selector.
    aggrelod::runtime::RuntimeFile cpp;
    std::string message;
    ASSERT_EQ(aggrelod::runtime::RuntimeFile::openMemory(bytes.data(), bytes.size(), cpp, message),
              aggrelod::runtime::FileStatus::Ok);
    aggrelod::runtime::Selector reference(cpp);
    aggrelod::runtime::Camera c;
    std::memcpy(c.position, camera.position, sizeof c.position);
    c.fovY = 1.0f;
    c.viewportHeight = 1080.0f;
    reference.selectFull(c, {4.0f, 0.75f});
    std::vector<uint32_t> a(cut.nodes, cut.nodes + cut.node_count), b(reference.cut().begin(), reference.cut().end());
    std::sort(a.begin(), a.end());
    std::sort(b.begin(), b.end());
    EXPECT_EQ(a, b);
    EXPECT_EQ(cut.proxy_count + cut.original_count >= cut.node_count, true);
    EXPECT_GT(cut.proxy_count, 0u);
    EXPECT_GT(cut.original_count, 0u);
    EXPECT_EQ(aglod_select(selector, &camera, 0.0f, 0.75f, &cut), AGLOD_INVALID_ARGUMENT);
    EXPECT_NE(std::string(aglod_last_error()).find("pixel_tolerance"), std::string::npos);
    aglod_selector_destroy(selector);
    aglod_close(file);
}

TEST(RuntimeCApi, BadInputGivesStatusAndMessage) {
    std::vector<uint8_t> bytes = syntheticBytes(20);
    bytes[100] ^= 1;
    aglod_file* file = reinterpret_cast<aglod_file*>(&bytes);  // must be reset to NULL
    EXPECT_EQ(aglod_open_memory(bytes.data(), bytes.size(), &file), AGLOD_CHECKSUM_MISMATCH);
    EXPECT_EQ(file, nullptr);
    EXPECT_STREQ(aglod_status_string(AGLOD_CHECKSUM_MISMATCH), "checksum mismatch");
    EXPECT_NE(std::string(aglod_last_error()), "");
    EXPECT_EQ(aglod_open_file("/nonexistent/x.aglod", &file), AGLOD_IO_ERROR);
    EXPECT_NE(std::string(aglod_last_error()).find("/nonexistent/x.aglod"), std::string::npos);
    EXPECT_EQ(aglod_open_file(nullptr, &file), AGLOD_INVALID_ARGUMENT);
    EXPECT_EQ(aglod_open_memory(bytes.data(), bytes.size(), nullptr), AGLOD_INVALID_ARGUMENT);
    // NULL handles are harmless everywhere.
    aglod_close(nullptr);
    aglod_selector_destroy(nullptr);
    EXPECT_EQ(aglod_selector_create(nullptr), nullptr);
    EXPECT_EQ(aglod_node_count(nullptr), 0u);
    aglod_cut cut;
    EXPECT_EQ(aglod_select(nullptr, nullptr, 1.0f, 1.0f, &cut), AGLOD_INVALID_ARGUMENT);
#ifdef AGGRELOD_HAVE_COLLISION
    EXPECT_EQ(aglod_collision_create(nullptr), nullptr);
    aglod_hit hit;
    const float o[3] = {0, 0, 0};
    EXPECT_EQ(aglod_raycast(nullptr, o, o, 1.0f, &hit), 0);
    EXPECT_EQ(aglod_collision_use_level(nullptr, 0), AGLOD_INVALID_ARGUMENT);
    aglod_collision_destroy(nullptr);
#endif
}

#ifdef AGGRELOD_HAVE_COLLISION
TEST(RuntimeCApi, RaycastReportsNodeAndObjects) {
    const std::vector<uint8_t> bytes = syntheticBytes(100);
    aglod_file* file = nullptr;
    ASSERT_EQ(aglod_open_memory(bytes.data(), bytes.size(), &file), AGLOD_OK);
    aglod_collision* collision = aglod_collision_create(file);
    ASSERT_NE(collision, nullptr) << aglod_last_error();
    // Straight down onto the first box, from above the scene: hits its top face.
    float lo[3], hi[3], sceneLo[3], sceneHi[3];
    ASSERT_EQ(aglod_node_bounds(file, 0, lo, hi), 1);
    ASSERT_EQ(aglod_scene_bounds(file, sceneLo, sceneHi), 1);
    const float origin[3] = {0.5f * (lo[0] + hi[0]), sceneHi[1] + 10.0f, 0.5f * (lo[2] + hi[2])};
    const float expected = origin[1] - hi[1];
    const float down[3] = {0, -1, 0};
    aglod_hit hit;
    ASSERT_EQ(aglod_raycast(collision, origin, down, 100.0f, &hit), 1);
    EXPECT_EQ(hit.node, 0u);
    EXPECT_NEAR(hit.distance, expected, 1e-4f);
    EXPECT_NEAR(hit.normal[1], 1.0f, 1e-6f);
    ASSERT_EQ(hit.object_count, 1u);
    EXPECT_EQ(aglod_occluded(collision, origin, down, expected - 0.1f), 0);
    EXPECT_EQ(aglod_occluded(collision, origin, down, expected + 0.1f), 1);
    // Coarsest level: the same ray hits a proxy standing for many objects, no later.
    uint32_t coarsest = 0;
    for (uint32_t n = 0; n < aglod_node_count(file); ++n)
        if (aglod_node_level(file, n) != AGLOD_LEAF_LEVEL) coarsest = std::max(coarsest, aglod_node_level(file, n));
    ASSERT_EQ(aglod_collision_use_level(collision, coarsest), AGLOD_OK);
    ASSERT_EQ(aglod_raycast(collision, origin, down, 100.0f, &hit), 1);
    EXPECT_NEAR(hit.distance, 10.0f, 1e-4f);  // the top of the whole scene's box
    EXPECT_EQ(hit.object_count, 100u);
    aglod_collision_destroy(collision);
    aglod_close(file);
}
#endif

TEST(RuntimeCApi, NodeMeshIsAViewOfTheFile) {
    const std::vector<uint8_t> bytes = syntheticBytes(50);
    aglod_file* file = nullptr;
    ASSERT_EQ(aglod_open_memory(bytes.data(), bytes.size(), &file), AGLOD_OK) << aglod_last_error();
    aggrelod::runtime::RuntimeFile cpp;
    std::string message;
    ASSERT_EQ(aggrelod::runtime::RuntimeFile::openMemory(bytes.data(), bytes.size(), cpp, message),
              aggrelod::runtime::FileStatus::Ok);
    size_t withTriangles = 0;
    for (uint32_t n = 0; n < aglod_node_count(file); ++n) {
        const float* positions = nullptr;
        const uint32_t* indices = nullptr;
        uint32_t vertexCount = 0, indexCount = 0;
        ASSERT_EQ(aglod_node_mesh(file, n, &positions, &vertexCount, &indices, &indexCount), 1);
        const auto v = cpp.vertices(n);
        const auto t = cpp.triangles(n);
        ASSERT_EQ(vertexCount, v.size / 3);
        ASSERT_EQ(indexCount, t.size);
        EXPECT_EQ(indexCount % 3, 0u);
        for (uint32_t i = 0; i < indexCount; ++i) EXPECT_LT(indices[i], vertexCount);
        if (vertexCount) {
            EXPECT_EQ(std::memcmp(positions, v.data, 3 * sizeof(float) * vertexCount), 0);
        }
        if (indexCount) ++withTriangles;
    }
    EXPECT_GT(withTriangles, 0u);
    const float* positions = reinterpret_cast<const float*>(&bytes);
    uint32_t vertexCount = 7;
    EXPECT_EQ(aglod_node_mesh(file, aglod_node_count(file), &positions, &vertexCount, nullptr, nullptr), 0);
    EXPECT_EQ(positions, nullptr);
    EXPECT_EQ(vertexCount, 0u);
    EXPECT_EQ(aglod_node_mesh(nullptr, 0, nullptr, nullptr, nullptr, nullptr), 0);
    aglod_close(file);
}
