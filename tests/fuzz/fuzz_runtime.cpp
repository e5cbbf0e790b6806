// SPDX-License-Identifier: AGPL-3.0-or-later
// libFuzzer target: the runtime reader (aglod_open_memory); on a file it accepts, selection
// and ray casts through the C API with cameras and rays taken from the input's last bytes.
#include <aggrelod_runtime.h>

#include "aglod_layout.h"

#include <cstdint>
#include <cstring>
#include <memory>
#include <vector>

namespace {
/// A float from the input's tail (any bit pattern: NaN, infinities and huge values included).
float floatAt(const uint8_t* data, size_t size, size_t k) {
    float v = 0;
    if (size >= 4 * (k + 1)) std::memcpy(&v, data + size - 4 * (k + 1), 4);
    return v;
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    // An exact, 16-byte aligned copy: ASan then sees any read past the end.
    std::unique_ptr<uint8_t[]> copy(new uint8_t[size + 16]);
    uint8_t* aligned = copy.get() + (16 - reinterpret_cast<uintptr_t>(copy.get()) % 16) % 16;
    std::memcpy(aligned, data, size);
    // Most inputs: re-sign the checksum, as a forger would, so that the structural checks
    // past it are fuzzed too.
    using namespace aggrelod::runtime::layout;
    if (size >= kHeaderSize && (size % 4) != 3) {
        const uint64_t total = loadU64(aligned + 16);
        if (total <= size) {
            const uint64_t sum = fileChecksum(aligned, size_t(total), kChecksumOffset);
            std::memcpy(aligned + kChecksumOffset, &sum, 8);
        }
    }
    aglod_file* file = nullptr;
    if (aglod_open_memory(aligned, size, &file) != AGLOD_OK) return 0;
    float min[3], max[3];
    aglod_scene_bounds(file, min, max);
    aglod_selector* selector = aglod_selector_create(file);
    if (selector) {
        aglod_cut cut{};
        const aglod_camera near = {{min[0], min[1], max[2] + 1.0f}, 1.0f, 720.0f};
        aglod_select(selector, &near, 1.0f, 0.5f, &cut);
        const aglod_camera forged = {{floatAt(data, size, 0), floatAt(data, size, 1), floatAt(data, size, 2)},
                                     floatAt(data, size, 3), floatAt(data, size, 4)};
        aglod_select(selector, &forged, floatAt(data, size, 5), floatAt(data, size, 6), &cut);
        aglod_view_camera view = {{0, 0, 10}, 1.0f, 720.0f, {0, 0, -1}, {0, 1, 0}, 1.5f, 0.1f, 0.0f};
        view.forward[0] = floatAt(data, size, 7);
        aglod_select_view(selector, &view, 1.0f, 0.5f, &cut);
        aglod_selector_destroy(selector);
    }
    aglod_collision* collision = aglod_collision_create(file);
    if (collision) {
        aglod_hit hit{};
        const float origin[3] = {0.5f * (min[0] + max[0]), 0.5f * (min[1] + max[1]), max[2] + 1.0f};
        const float down[3] = {0, 0, -1};
        aglod_raycast(collision, origin, down, 1e30f, &hit);
        const float o2[3] = {floatAt(data, size, 0), floatAt(data, size, 1), floatAt(data, size, 2)};
        const float d2[3] = {floatAt(data, size, 3), floatAt(data, size, 4), floatAt(data, size, 5)};
        aglod_raycast(collision, o2, d2, floatAt(data, size, 6), &hit);
        aglod_occluded(collision, o2, d2, floatAt(data, size, 7));
        aglod_collision_use_distance_cut(collision, o2, 0.01f);
        aglod_collision_use_level(collision, 0);
        aglod_collision_destroy(collision);
    }
    aglod_close(file);
    return 0;
}
