// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod module (internal): index order of proxy meshes for the GPU's vertex cache
// (docs/design.md §2.6). The only place that calls meshoptimizer, so it can be swapped.
#pragma once

#include <cstdint>
#include <vector>

namespace aggrelod::detail {

/// Reorders the triangles of an indexed mesh for the post-transform vertex cache
/// (meshoptimizer's meshopt_optimizeVertexCache, Forsyth's algorithm), then numbers the
/// vertices by first use and reorders positions (3 floats each) and per-triangle colours
/// (4 floats each, may be empty) to match. Geometry and orientation are unchanged.
/// Deterministic.
void optimizeVertexCache(std::vector<float>& positions, std::vector<uint32_t>& indices, std::vector<float>& faceColors);

}  // namespace aggrelod::detail
