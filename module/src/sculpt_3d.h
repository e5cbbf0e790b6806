// SPDX-License-Identifier: AGPL-3.0-or-later
// Sculpting one level (docs/design.md §2.4; paper Sections 3.3 and 4.4) and extracting the
// aggregate surfaces (docs/design.md §2.4 step 5).
#pragma once

#include "edge_limits.h"
#include "free_space.h"

#include <aggrelod/aggregate3d.h>

#include <memory>
#include <vector>

namespace aggrelod::detail {

/// Connection that must survive carving: models a and b joined at this level, with the
/// points where they come closest.
struct ProtectedConnection {
    uint32_t modelA = 0, modelB = 0;
    double pointA[3] = {0, 0, 0};
    double pointB[3] = {0, 0, 0};
};

/// Fills space.tetEdgeLength, tetEdgePair and surfaceTetsOfModel (after the pairs are
/// built): every level then only looks them up. threadCount: as Settings3D::threadCount.
void precomputeTetEdges(FreeSpace& space, int threadCount);

/// Buffers that sculptLevel and extractSurfaces reuse from one level to the next (each call
/// fills them afresh: reuse never changes a result, it only saves allocating and
/// page-faulting tens of megabytes per level). One thread at a time.
class SculptScratch {
public:
    SculptScratch();
    ~SculptScratch();
    struct Buffers;
    std::unique_ptr<Buffers> buffers;
    std::vector<int> label, baselineLabel, surfaceTets;  ///< for the caller's per-level outputs
};

struct LevelShapeRequest {
    const std::vector<uint32_t>* modelGroup = nullptr;  ///< per model: group index at this level
    size_t groupCount = 0;
    const EdgeLimits* limits = nullptr;
    std::vector<ProtectedConnection> connections;       ///< joined pairs to keep connected
    bool cleanUp = true;  ///< make the solids manifold (off for volume-only baselines)
    /// Optional second set of limits (the constant baseline): carved from the same initial
    /// labels and protected connections, without clean-up (volume only).
    const EdgeLimits* baselineLimits = nullptr;
};

/// Labels every tet with the group whose solid contains it (-1: not in any aggregate).
/// Object interiors take their model's group; free tets are kept or carved. When
/// request.baselineLimits is set, *baselineLabel gets the labels carved with those limits.
/// surfaceTets (optional) gets, ascending, every tet that can hold a face of the surfaces:
/// a superset of the free tets in a solid and of the solid object tets on a model surface
/// (for extractSurfaces, so it need not scan the whole mesh).
void sculptLevel(const FreeSpace& space, const LevelShapeRequest& request, std::vector<int>& tetLabel,
                 std::vector<int>* baselineLabel = nullptr, std::vector<int>* surfaceTets = nullptr,
                 SculptScratch* scratch = nullptr);

/// Builds the closed, edge-manifold, outward surface of every group from the tet labels.
/// aggregates[g] gets positions, indices and componentCount. surfaceTets (optional): the
/// list sculptLevel gave; without it every tet is scanned (same result).
void extractSurfaces(const FreeSpace& space, const std::vector<int>& tetLabel, size_t groupCount,
                     std::vector<Aggregate>& aggregates, const std::vector<int>* surfaceTets = nullptr,
                     SculptScratch* scratch = nullptr);

}  // namespace aggrelod::detail
