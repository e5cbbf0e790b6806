// SPDX-License-Identifier: AGPL-3.0-or-later
// Edge limits (paper Section 3.3, the aggregate function F; docs/design.md §2.4 step 3): F of
// every model pair at one threshold, evaluated once per level from the pair's distance and
// the statistics of its free-space edges, so that carving on several threads only looks
// limits up and never calls user code. One record and one evaluation for 2D and 3D.
#pragma once

#include "free_space.h"
#include "free_space_2d.h"

#include <aggrelod/aggregate3d.h>

#include <vector>

namespace aggrelod::detail {

/// F of every model pair at one level, world units.
struct EdgeLimits {
    double sameModel = 0;      ///< F for an edge with both ends on one model
    double unpaired = 0;       ///< F for an edge with no pair: a Steiner end (2D), two models without statistics (3D)
    double delta = 0;          ///< the level threshold
    std::vector<double> pair;  ///< per pair of the free space's `pairs`
    double smallest = 0;       ///< the least of these limits (NaN left out): no element whose edges are all this short is carved
};

/// Evaluates `function` for every 2D pair at threshold delta; the pair's distance is its
/// shortest connection.
EdgeLimits computeEdgeLimits(const FreeSpace2D& space, double delta, const AggregateFunction& function);

/// Evaluates `function` for every 3D pair at threshold delta; the pair's distance is the
/// exact one or the shortest free-space edge, as `distance` says.
EdgeLimits computeEdgeLimits(const FreeSpace& space, double delta, const AggregateFunction& function,
                             DistanceMode distance);

}  // namespace aggrelod::detail
