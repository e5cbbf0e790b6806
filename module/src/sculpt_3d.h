// Sculpting one level (DESIGN 2.4; paper Sections 3.3 and 4.4) and extracting the
// aggregate surfaces (DESIGN 2.4 step 5).
#pragma once

#include "free_space.h"

#include <aggrelod/aggregate3d.h>

#include <vector>

namespace aggrelod::detail {

/// Connection that must survive carving: models a and b joined at this level, with the
/// points where they come closest.
struct ProtectedConnection {
    uint32_t modelA = 0, modelB = 0;
    double pointA[3] = {0, 0, 0};
    double pointB[3] = {0, 0, 0};
};

struct LevelShapeRequest {
    const std::vector<uint32_t>* modelGroup = nullptr;  ///< per model: group index at this level
    size_t groupCount = 0;
    double delta = 0;
    const AggregateFunction* function = nullptr;
    DistanceMode distance = DistanceMode::Exact;
    std::vector<ProtectedConnection> connections;       ///< joined pairs to keep connected
    bool cleanUp = true;  ///< make the solids manifold (off for volume-only baselines)
};

/// Labels every tet with the group whose solid contains it (-1: not in any aggregate).
/// Object interiors take their model's group; free tets are kept or carved.
void sculptLevel(const FreeSpace& space, const LevelShapeRequest& request, std::vector<int>& tetLabel);

/// Builds the closed, edge-manifold, outward surface of every group from the tet labels.
/// aggregates[g] gets positions, indices and componentCount.
void extractSurfaces(const FreeSpace& space, const std::vector<int>& tetLabel, size_t groupCount,
                     std::vector<Aggregate>& aggregates);

}  // namespace aggrelod::detail
