// aggrelod module (internal): proxy simplification (DESIGN section 2.6). The only place that
// calls meshoptimizer, so the simplifier can be swapped.
#pragma once

#include <cstdint>
#include <vector>

namespace aggrelod::detail {

/// Simplifies an indexed triangle mesh by edge collapses (meshoptimizer's meshopt_simplify)
/// until the next collapse would exceed `targetError` (world units; meshoptimizer's own
/// quadric estimate, not a guarantee: measure the result). positions: 3 * vertexCount
/// floats; indices: 3 * triangleCount. The output keeps only the used vertices, numbered
/// by first use. targetError <= 0, an empty mesh or a mesh that would vanish copies the
/// input. Deterministic.
void simplifyMesh(const std::vector<float>& positions, const std::vector<uint32_t>& indices,
                  double targetError, std::vector<float>& outPositions,
                  std::vector<uint32_t>& outIndices);

}  // namespace aggrelod::detail
