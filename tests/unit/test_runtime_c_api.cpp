// SPDX-License-Identifier: MIT
// The C API (aggrelod_runtime.h): open/close, statuses and messages, selection views,
// raycast, and NULL-safety of every entry point.
#include <aggrelod_runtime.h>

#include <aggrelod/runtime_build.h>
#include <aggrelod/runtime_file.h>
#include <aggrelod/selection.h>

#include "synthetic_hierarchy.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

using aggrelod::testing::makeSyntheticHierarchy;

namespace {
std::vector<uint8_t> syntheticBytes(uint32_t objects) {
    std::vector<uint8_t> bytes;
    std::string error;
    EXPECT_TRUE(aggrelod::runtime::writeRuntimeFile(makeSyntheticHierarchy(objects, 9), bytes, error)) << error;
    return bytes;
}
// The same bytes through the C API and the C++ reader.
void openBoth(const std::vector<uint8_t>& bytes, aglod_file*& file, aggrelod::runtime::RuntimeFile& cpp) {
    ASSERT_EQ(aglod_open_memory(bytes.data(), bytes.size(), &file), AGLOD_OK) << aglod_last_error();
    std::string message;
    ASSERT_EQ(aggrelod::runtime::RuntimeFile::openMemory(bytes.data(), bytes.size(), cpp, message),
              aggrelod::runtime::FileStatus::Ok) << message;
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
    // Drawing costs: the same as the C++ call; bad arguments refused.
    std::vector<uint32_t> originalTriangles(aglod_object_count(file), 12u);
    ASSERT_EQ(aglod_selector_set_draw_costs(selector, originalTriangles.data(), 8.0f), AGLOD_OK);
    reference.setDrawCosts(originalTriangles.data(), 8.0f);
    ASSERT_EQ(aglod_select(selector, &camera, 4.0f, 0.75f, &cut), AGLOD_OK);
    reference.selectFull(c, {4.0f, 0.75f});
    a.assign(cut.nodes, cut.nodes + cut.node_count);
    b.assign(reference.cut().begin(), reference.cut().end());
    std::sort(a.begin(), a.end());
    std::sort(b.begin(), b.end());
    EXPECT_EQ(a, b);
    EXPECT_EQ(aglod_selector_set_draw_costs(nullptr, nullptr, 1.0f), AGLOD_INVALID_ARGUMENT);
    EXPECT_EQ(aglod_selector_set_draw_costs(selector, nullptr, -1.0f), AGLOD_INVALID_ARGUMENT);
    EXPECT_EQ(aglod_selector_set_draw_costs(selector, nullptr, INFINITY), AGLOD_INVALID_ARGUMENT);
    EXPECT_NE(std::string(aglod_last_error()).find("triangles_per_draw_call"), std::string::npos);
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
    aggrelod::runtime::RuntimeFile cpp;
    ASSERT_NO_FATAL_FAILURE(openBoth(bytes, file, cpp));
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

TEST(RuntimeCApi, NodeNormalsAndColorsAreViewsOfTheFile) {
    const aggrelod::runtime::BuildArrays p = makeSyntheticHierarchy(40, 9, 4, 1, 1.0f, 1);
    std::vector<uint8_t> bytes;
    std::string error;
    ASSERT_TRUE(aggrelod::runtime::writeRuntimeFile(p, bytes, error)) << error;
    aglod_file* file = nullptr;
    ASSERT_EQ(aglod_open_memory(bytes.data(), bytes.size(), &file), AGLOD_OK) << aglod_last_error();
    size_t objectLods = 0;
    for (uint32_t n = 0; n < aglod_node_count(file); ++n) {
        const aggrelod::runtime::NodeRecord& b = p.nodes[n];
        const float* normals = nullptr;
        const uint8_t* colors = nullptr;
        uint32_t normalCount = 0, colorCount = 0, vertexCount = 0;
        ASSERT_EQ(aglod_node_mesh(file, n, nullptr, &vertexCount, nullptr, nullptr), 1);
        ASSERT_EQ(aglod_node_normals(file, n, &normals, &normalCount), 1);
        ASSERT_EQ(aglod_node_colors(file, n, &colors, &colorCount), 1);
        ASSERT_EQ(normalCount, vertexCount);
        ASSERT_EQ(colorCount, vertexCount);
        ASSERT_EQ(vertexCount, b.vertexCount);
        EXPECT_EQ(std::memcmp(normals, &p.normals[3 * size_t(b.firstVertex)], 12 * size_t(vertexCount)), 0) << n;
        EXPECT_EQ(std::memcmp(colors, &p.colors[4 * size_t(b.firstVertex)], 4 * size_t(vertexCount)), 0) << n;
        objectLods += aglod_node_level(file, n) == AGLOD_OBJECT_LOD_LEVEL;
    }
    EXPECT_EQ(objectLods, 40u);
    // The colour bytes decode to linear RGBA as the C++ runtime does.
    const uint8_t rgba[4] = {188, 0, 255, 128};
    float linear[4];
    aglod_color_to_linear(rgba, linear);
    EXPECT_NEAR(linear[0], 0.5f, 0.003f);
    EXPECT_EQ(linear[1], 0.0f);
    EXPECT_EQ(linear[2], 1.0f);
    EXPECT_NEAR(linear[3], 128 / 255.0f, 1e-6f);
    aglod_color_to_linear(nullptr, linear);  // NULL-safe
    // Out of range and NULL: 0 and empty outputs.
    const float* normals = reinterpret_cast<const float*>(&bytes);
    const uint8_t* colors = bytes.data();
    uint32_t count = 7;
    EXPECT_EQ(aglod_node_normals(file, aglod_node_count(file), &normals, &count), 0);
    EXPECT_EQ(normals, nullptr);
    EXPECT_EQ(count, 0u);
    count = 7;
    EXPECT_EQ(aglod_node_colors(file, aglod_node_count(file), &colors, &count), 0);
    EXPECT_EQ(colors, nullptr);
    EXPECT_EQ(count, 0u);
    EXPECT_EQ(aglod_node_normals(nullptr, 0, nullptr, nullptr), 0);
    EXPECT_EQ(aglod_node_colors(nullptr, 0, nullptr, nullptr), 0);
    aglod_close(file);
}

TEST(RuntimeCApi, ViewSelectionCullsAndReportsCutChanges) {
    const std::vector<uint8_t> bytes = syntheticBytes(400);
    aglod_file* file = nullptr;
    aggrelod::runtime::RuntimeFile cpp;
    ASSERT_NO_FATAL_FAILURE(openBoth(bytes, file, cpp));
    aglod_selector* selector = aglod_selector_create(file);
    ASSERT_NE(selector, nullptr);
    aglod_cut_changes changes;
    ASSERT_EQ(aglod_selector_changes(selector, &changes), 1);
    ASSERT_EQ(changes.entered_count, uint32_t(cpp.roots().size));  // construction: the roots entered
    EXPECT_EQ(changes.left_count, 0u);

    // In the middle of the city, looking along +x: the same cut and culled nodes as the C++
    // selector with the same camera; far = 0 means no far plane.
    float lo[3], hi[3];
    ASSERT_EQ(aglod_scene_bounds(file, lo, hi), 1);
    aglod_view_camera view = {{0.5f * (lo[0] + hi[0]), 10.0f, 0.5f * (lo[2] + hi[2])}, 1.0f, 1080.0f,
                              {1, 0, 0}, {0, 1, 0}, 1.5f, 0.0f, 0.0f};
    aglod_cut cut;
    ASSERT_EQ(aglod_select_view(selector, &view, 2.0f, 0.75f, &cut), AGLOD_OK) << aglod_last_error();
    aggrelod::runtime::Selector reference(cpp);
    aggrelod::runtime::ViewCamera c;
    std::memcpy(c.position, view.position, sizeof c.position);
    c.fovY = 1.0f;
    c.viewportHeight = 1080.0f;
    c.aspect = 1.5f;
    c.forward[0] = 1; c.forward[1] = 0; c.forward[2] = 0;
    reference.select(c, {2.0f, 0.75f});
    std::vector<uint32_t> a(cut.nodes, cut.nodes + cut.node_count), b(reference.cut().begin(), reference.cut().end());
    std::sort(a.begin(), a.end());
    std::sort(b.begin(), b.end());
    EXPECT_EQ(a, b);
    uint32_t culledCount = 0;
    const uint32_t* culled = aglod_culled_nodes(selector, &culledCount);
    ASSERT_GT(culledCount, 0u);
    EXPECT_EQ(culledCount, uint32_t(reference.culledNodes().size));
    std::vector<uint32_t> ca(culled, culled + culledCount), cb(reference.culledNodes().begin(), reference.culledNodes().end());
    std::sort(ca.begin(), ca.end());
    std::sort(cb.begin(), cb.end());
    EXPECT_EQ(ca, cb);
    // The changes since construction: everything drawn entered, the roots (refined) left.
    ASSERT_EQ(aglod_selector_changes(selector, &changes), 1);
    EXPECT_EQ(changes.entered_count, cut.node_count);
    std::vector<uint32_t> entered(changes.entered, changes.entered + changes.entered_count);
    std::sort(entered.begin(), entered.end());
    EXPECT_EQ(entered, a);

    // Turning around: what was drawn leaves, the cut of the other half enters.
    const std::vector<uint32_t> before = a;
    view.forward[0] = -1;
    ASSERT_EQ(aglod_select_view(selector, &view, 2.0f, 0.75f, &cut), AGLOD_OK);
    ASSERT_EQ(aglod_selector_changes(selector, &changes), 1);
    std::vector<uint32_t> after(cut.nodes, cut.nodes + cut.node_count), left(changes.left, changes.left + changes.left_count);
    std::sort(after.begin(), after.end());
    std::sort(left.begin(), left.end());
    std::vector<uint32_t> expectedLeft;
    std::set_difference(before.begin(), before.end(), after.begin(), after.end(), std::back_inserter(expectedLeft));
    EXPECT_EQ(left, expectedLeft);
    EXPECT_GT(changes.left_count, 0u);
    EXPECT_GT(changes.entered_count, 0u);

    // aglod_select afterwards culls nothing.
    aglod_camera plain = {{view.position[0], view.position[1], view.position[2]}, 1.0f, 1080.0f};
    ASSERT_EQ(aglod_select(selector, &plain, 2.0f, 0.75f, &cut), AGLOD_OK);
    aglod_culled_nodes(selector, &culledCount);
    EXPECT_EQ(culledCount, 0u);

    // Bad cameras are refused with a message; NULLs are safe.
    aglod_view_camera bad = view;
    bad.forward[0] = 0;
    EXPECT_EQ(aglod_select_view(selector, &bad, 2.0f, 0.75f, &cut), AGLOD_INVALID_ARGUMENT);
    EXPECT_NE(std::string(aglod_last_error()).find("forward"), std::string::npos);
    bad = view;
    bad.up[0] = -1; bad.up[1] = 0;  // parallel to forward
    EXPECT_EQ(aglod_select_view(selector, &bad, 2.0f, 0.75f, &cut), AGLOD_INVALID_ARGUMENT);
    bad = view;
    bad.aspect = 0;
    EXPECT_EQ(aglod_select_view(selector, &bad, 2.0f, 0.75f, &cut), AGLOD_INVALID_ARGUMENT);
    bad = view;
    bad.near_distance = 5;
    bad.far_distance = 2;
    EXPECT_EQ(aglod_select_view(selector, &bad, 2.0f, 0.75f, &cut), AGLOD_INVALID_ARGUMENT);
    EXPECT_EQ(aglod_select_view(selector, nullptr, 2.0f, 0.75f, &cut), AGLOD_INVALID_ARGUMENT);
    EXPECT_EQ(aglod_select_view(nullptr, &view, 2.0f, 0.75f, &cut), AGLOD_INVALID_ARGUMENT);
    EXPECT_EQ(aglod_culled_nodes(nullptr, &culledCount), nullptr);
    EXPECT_EQ(culledCount, 0u);
    EXPECT_EQ(aglod_selector_changes(nullptr, &changes), 0);
    EXPECT_EQ(aglod_selector_changes(selector, nullptr), 0);
    aglod_selector_destroy(selector);
    aglod_close(file);
}
