// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod module: vertex-cache order of proxy meshes (mesh_optimize.h) with meshoptimizer.
#include "mesh_optimize.h"

#include <meshoptimizer.h>

#include <algorithm>
#include <array>

namespace aggrelod::detail {

void optimizeVertexCache(std::vector<float>& positions, std::vector<uint32_t>& indices, std::vector<float>& faceColors) {
    const size_t vertexCount = positions.size() / 3, triangleCount = indices.size() / 3;
    if (triangleCount == 0) return;
    std::vector<uint32_t> optimized(indices.size());
    meshopt_optimizeVertexCache(optimized.data(), indices.data(), indices.size(), vertexCount);
    // Which input triangle each output triangle is: meshoptimizer keeps every triangle's
    // corner order up to rotation, so the triangle is found by its sorted corners.
    std::vector<std::pair<std::array<uint32_t, 3>, uint32_t>> byCorners(triangleCount);
    auto sorted = [](const uint32_t* t) {
        std::array<uint32_t, 3> c = {t[0], t[1], t[2]};
        std::sort(c.begin(), c.end());
        return c;
    };
    for (size_t t = 0; t < triangleCount; ++t) byCorners[t] = {sorted(&indices[3 * t]), uint32_t(t)};
    std::sort(byCorners.begin(), byCorners.end());
    std::vector<float> colors;
    if (faceColors.size() == 4 * triangleCount) {
        colors.resize(faceColors.size());
        for (size_t t = 0; t < triangleCount; ++t) {
            const auto key = sorted(&optimized[3 * t]);
            const auto it = std::lower_bound(byCorners.begin(), byCorners.end(), std::make_pair(key, 0u));
            std::copy_n(&faceColors[4 * size_t(it->second)], 4, &colors[4 * t]);
        }
        faceColors = std::move(colors);
    }
    std::vector<uint32_t> remap(vertexCount, UINT32_MAX);
    std::vector<float> reordered;
    reordered.reserve(positions.size());
    uint32_t next = 0;
    for (uint32_t& i : optimized) {
        if (remap[i] == UINT32_MAX) {
            remap[i] = next++;
            reordered.insert(reordered.end(), positions.begin() + 3 * size_t(i), positions.begin() + 3 * size_t(i) + 3);
        }
        i = remap[i];
    }
    positions = std::move(reordered);
    indices = std::move(optimized);
}

}  // namespace aggrelod::detail
