// SPDX-License-Identifier: AGPL-3.0-or-later
// Neighbourhood graph -> dendrogram -> levels (docs/design.md §2.3; paper Section 3.2, Algorithm 1).
// Shared by 2D and 3D: models are plain indices, weights are distances in world units.
#pragma once

#include <aggrelod/aggregate_common.h>

#include <cstdint>
#include <string>
#include <vector>

namespace aggrelod {

/// One edge of the neighbourhood graph between models a and b (a != b).
struct GraphEdge {
    uint32_t a = 0, b = 0;
    double weight = 0;  ///< distance between the models, world units
};

/// Kruskal merges: edges sorted by (weight, smaller id, larger id, position in `edges`),
/// merged with union-find. Returns the dendrogram's merges in ascending height (at most
/// modelCount - 1). mergeEdge (optional): per merge, the index into `edges` of its edge.
std::vector<Merge> kruskalMerges(size_t modelCount, const std::vector<GraphEdge>& edges,
                                 std::vector<uint32_t>* mergeEdge = nullptr);

/// Groups at threshold delta: models joined by merges with height < delta.
/// Returns, per model, its group index; groups are numbered 0.. in order of their smallest model.
/// `groupCount` (optional) receives the number of groups.
std::vector<uint32_t> groupsAtThreshold(size_t modelCount, const std::vector<Merge>& merges, double delta,
                                        size_t* groupCount = nullptr);

/// Explicit thresholds must each be a finite number >= 0 (world units). Returns false, with
/// the message both pipelines report, when one is not (NaN would also break the sort of the
/// levels).
bool validThresholds(const std::vector<double>& deltas, std::string& problem);

/// Automatic thresholds: `levelCount` targets on a geometric series between the smallest and
/// largest merge height; each is moved to just above a merge height, so every level changes
/// the grouping, the first joins the closest pair and the last joins every connected model.
/// Returns ascending, distinct deltas (fewer than levelCount when there are fewer merges).
std::vector<double> automaticDeltas(const std::vector<Merge>& merges, int levelCount);

}  // namespace aggrelod
