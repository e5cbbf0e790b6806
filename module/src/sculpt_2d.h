// SPDX-License-Identifier: AGPL-3.0-or-later
// Sculpting one 2D level (docs/design.md §2.4; paper Section 3.3) and turning the kept triangles
// into OGC-valid polygons with holes.
#pragma once

#include "edge_limits.h"
#include "free_space_2d.h"

#include <vector>

namespace aggrelod::detail {

/// The fans of free faces that can carry each merge's shortest connection to its two models
/// (docs/design.md §2.4 step 4), walked once for all levels. The merges are kept in `order`, by their
/// pair's first best face (neighbouring merges touch neighbouring faces).
/// For the merge at position p of `order`, best face i (of the pair's two) and model s (0:
/// pair.a, 1: pair.b), slot 4p + 2i + s lists the walks around the model's vertices from that
/// face that reach the model's interior, in walk order. A level keeps the least-area one whose
/// faces are all kept in the group and no longer than delta.
struct ConnectionFans2D {
    std::vector<uint32_t> pair;       ///< per merge: index into space.pairs
    std::vector<uint32_t> order;      ///< the merges, by their pair's first best face
    std::vector<uint32_t> slotBegin;  ///< 4 * order.size() + 1: candidates of each slot
    std::vector<uint32_t> pathBegin;  ///< per candidate, + 1: its faces are faces[pathBegin[c], pathBegin[c + 1])
    std::vector<double> pathArea;     ///< per candidate: total area of its faces
    std::vector<double> pathLongest;  ///< per candidate: longest edge of its faces (0 if none)
    std::vector<int> faces;
};

/// mergePair: per merge of the dendrogram (ascending height), its index into space.pairs.
ConnectionFans2D computeConnectionFans2D(const FreeSpace2D& space, const std::vector<uint32_t>& mergePair, int threadCount);

/// Labels every face with the group whose aggregate contains it (-1: in none).
/// The first `joinedMerges` merges (those of this level) keep their shortest connection
/// (docs/design.md §2.4 step 4), through `fans`.
void sculptLevel2D(const FreeSpace2D& space, const std::vector<uint32_t>& modelGroup, const EdgeLimits& limits,
                   const ConnectionFans2D& fans, size_t joinedMerges, std::vector<int>& faceLabel);

/// Total area and boundary length of the labelled faces (all groups).
Measures2D measureLabels2D(const FreeSpace2D& space, const std::vector<int>& faceLabel);

/// Polygons with holes of every group: aggregates[g].polygons (exterior CCW, holes CW,
/// parts touching at a point split apart) and aggregates[g].measures. groupModel (optional,
/// per group): its model when it has only one, else -1; such a group with no kept free face
/// takes space.modelPolygons (when there are any) instead of being traced.
void extractPolygons2D(const FreeSpace2D& space, const std::vector<int>& faceLabel, size_t groupCount,
                       std::vector<Aggregate2D>& aggregates, const std::vector<int>* groupModel = nullptr);

/// Convex hull (counter-clockwise, open ring) of x y pairs; Andrew's monotone chain.
std::vector<double> convexHull2D(std::vector<double> points);

}  // namespace aggrelod::detail
