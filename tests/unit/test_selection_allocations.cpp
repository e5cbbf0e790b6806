// SPDX-License-Identifier: MIT
// The selector's promise (runtime/include/aggrelod/selection.h): it allocates once, at
// construction, and nothing per frame. This executable replaces the global operator new and
// counts every allocation made while frames are selected: select (incremental, with
// hysteresis), selectFull, select with a ViewCamera (frustum culling), selectByDistance and
// reset, over a flight that refines and coarsens every level of a synthetic city. Its own
// executable, without sanitizers, because AddressSanitizer replaces operator new itself.
#include <aggrelod/runtime_file.h>
#include <aggrelod/selection.h>

#include "synthetic_hierarchy.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <new>

namespace {
std::atomic<size_t> gAllocations{0};
}  // namespace

void* operator new(size_t size) {
    ++gAllocations;
    if (void* p = std::malloc(size ? size : 1)) return p;
    throw std::bad_alloc();
}
void* operator new[](size_t size) { return operator new(size); }
void* operator new(size_t size, const std::nothrow_t&) noexcept {
    ++gAllocations;
    return std::malloc(size ? size : 1);
}
void* operator new[](size_t size, const std::nothrow_t& tag) noexcept { return operator new(size, tag); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, size_t) noexcept { std::free(p); }
void operator delete[](void* p, size_t) noexcept { std::free(p); }

namespace {

using namespace aggrelod::runtime;

TEST(SelectionAllocations, NoAllocationPerFrameInAnySelectionCall) {
    std::vector<uint8_t> bytes;
    std::string error;
    ASSERT_TRUE(writeRuntimeFile(aggrelod::testing::makeSyntheticHierarchy(400, 7), bytes, error)) << error;
    RuntimeFile file;
    ASSERT_EQ(RuntimeFile::openMemory(bytes.data(), bytes.size(), file, error), FileStatus::Ok) << error;
    float lo[3] = {1e30f, 1e30f, 1e30f}, hi[3] = {-1e30f, -1e30f, -1e30f};
    for (uint32_t r : file.roots())
        for (int k = 0; k < 3; ++k) {
            lo[k] = std::min(lo[k], file.node(r).boundsMin[k]);
            hi[k] = std::max(hi[k], file.node(r).boundsMax[k]);
        }
    const float centre[3] = {(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, (lo[2] + hi[2]) / 2};
    const float size = std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                                 (hi[2] - lo[2]) * (hi[2] - lo[2]));

    Selector selector(file);
    std::vector<uint32_t> costs(file.objectCount(), 500);
    selector.setDrawCosts(costs.data(), Selector::kDefaultTrianglesPerDrawCall);
    SelectionSettings settings;
    uint32_t sawLevels = 0, sawLeaves = 0, sawCulled = 0, sawChanges = 0;
    const size_t before = gAllocations.load();
    // A flight from far away into the scene and out again, turning: 600 frames.
    for (int frame = 0; frame < 600; ++frame) {
        const float t = float(frame) / 599.0f;
        const float distance = size * std::pow(100.0f, std::fabs(2 * t - 1)) * 0.05f;  // 5 diameters .. 0.05
        const float angle = 6.2831853f * 2 * t;
        ViewCamera camera;
        camera.position[0] = centre[0] + distance * std::cos(angle);
        camera.position[1] = centre[1] + distance * std::sin(angle);
        camera.position[2] = centre[2] + 0.3f * distance;
        for (int k = 0; k < 3; ++k) camera.forward[k] = centre[k] - camera.position[k];
        camera.up[0] = 0, camera.up[1] = 0, camera.up[2] = 1;
        camera.viewportHeight = 1080;
        switch (frame % 5) {
            case 0: selector.select(static_cast<const Camera&>(camera), settings); break;
            case 1: selector.selectFull(camera, settings); break;
            case 2: selector.select(camera, settings); break;
            case 3: selector.selectByDistance(camera.position, 0.01f); break;
            default:
                if (frame % 50 == 4) selector.reset();
                selector.select(static_cast<const Camera&>(camera), settings);
        }
        sawLevels += selector.proxyNodes().size > 0;
        sawLeaves += selector.originalObjects().size > 0;
        sawCulled += selector.culledNodes().size > 0;
        sawChanges += selector.entered().size + selector.left().size > 0;
    }
    const size_t allocations = gAllocations.load() - before;
    EXPECT_EQ(allocations, 0u) << "allocations during 600 frames of selection";
    // The flight exercised the rule: proxies and originals drawn, nodes culled, cuts changed.
    EXPECT_GT(sawLevels, 0u);
    EXPECT_GT(sawLeaves, 0u);
    EXPECT_GT(sawCulled, 0u);
    EXPECT_GT(sawChanges, 100u);
}

// The counter itself works (else the test above would pass on nothing).
TEST(SelectionAllocations, TheCounterSeesAllocations) {
    const size_t before = gAllocations.load();
    std::vector<int>* v = new std::vector<int>(1000, 1);
    const size_t after = gAllocations.load();
    delete v;
    EXPECT_GE(after - before, 2u);
}

}  // namespace
