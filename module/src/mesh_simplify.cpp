// aggrelod module: proxy simplification with meshoptimizer (DESIGN section 2.6).
// meshoptimizer 0.18 takes the target error relative to the mesh extent (largest side of
// its bounding box); it is converted here from world units.
#include "mesh_simplify.h"

#include <meshoptimizer.h>

#include <algorithm>
#include <limits>

namespace aggrelod::detail {

void simplifyMesh(const std::vector<float>& positions, const std::vector<uint32_t>& indices,
                  double targetError, std::vector<float>& outPositions,
                  std::vector<uint32_t>& outIndices) {
    const size_t vertexCount = positions.size() / 3;
    float lo[3], hi[3];
    for (int c = 0; c < 3; ++c) {
        lo[c] = std::numeric_limits<float>::infinity();
        hi[c] = -std::numeric_limits<float>::infinity();
    }
    for (size_t v = 0; v < vertexCount; ++v)
        for (int c = 0; c < 3; ++c) {
            lo[c] = std::min(lo[c], positions[3 * v + c]);
            hi[c] = std::max(hi[c], positions[3 * v + c]);
        }
    const double extent = vertexCount ? std::max({double(hi[0]) - lo[0], double(hi[1]) - lo[1], double(hi[2]) - lo[2]}) : 0.0;
    std::vector<uint32_t> kept;
    if (targetError > 0 && extent > 0 && indices.size() >= 3) {
        kept.resize(indices.size());
        // target_index_count 0: stop on the error bound only.
        const size_t count = meshopt_simplify(kept.data(), indices.data(), indices.size(), positions.data(),
                                              vertexCount, 3 * sizeof(float), 0,
                                              static_cast<float>(targetError / extent), 0, nullptr);
        kept.resize(count);
        if (kept.empty()) kept = indices;  // never simplify a mesh away: keep it exact
    } else {
        kept = indices;
    }
    // Compact: vertices numbered by first use.
    std::vector<uint32_t> remap(vertexCount, UINT32_MAX);
    outPositions.clear();
    outIndices.resize(kept.size());
    uint32_t next = 0;
    for (size_t i = 0; i < kept.size(); ++i) {
        const uint32_t v = kept[i];
        if (remap[v] == UINT32_MAX) {
            remap[v] = next++;
            outPositions.insert(outPositions.end(), positions.begin() + 3 * size_t(v), positions.begin() + 3 * size_t(v) + 3);
        }
        outIndices[i] = remap[v];
    }
}

}  // namespace aggrelod::detail
