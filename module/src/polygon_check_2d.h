// SPDX-License-Identifier: AGPL-3.0-or-later
// Input checks for 2D polygons (docs/design.md §2.1 input rules): finite coordinates, rings of at
// least 3 distinct vertices with non-zero area, no self-intersecting ring, no crossing rings
// within a polygon; and which polygons touch or overlap each other (merged into one model).
#pragma once

#include <aggrelod/aggregate2d.h>

#include <string>
#include <utility>
#include <vector>

namespace aggrelod::detail {

struct CheckedPolygons {
    std::vector<Polygon2D> parts;            ///< accepted polygons, repeated vertices removed, exterior CCW, holes CW
    std::vector<uint32_t> partFeature;       ///< per part: index of its feature
    std::vector<std::pair<uint32_t, uint32_t>> touchingParts;  ///< part pairs (a < b) whose boundaries meet
    std::vector<char> featureAccepted;       ///< per feature
};

/// Checks every feature; a feature with any bad ring is rejected as a whole (Error diagnostic
/// naming the feature, polygon, ring and place). Deterministic. The same as cleanPolygons()
/// then checkPolygonContacts().
void checkPolygons(const std::vector<Feature2D>& features, CheckedPolygons& out,
                   std::vector<Diagnostic>& diagnostics);

/// What the first step of the checks hands to the second.
struct PolygonCheckProgress {
    std::vector<uint32_t> partIndexInFeature;  ///< per part: its polygon's index in its feature
    std::vector<std::string> droppedParts;     ///< per feature: first problem found, for the message
};

/// Step 1 (linear, cheap): every ring finite, >= 3 distinct vertices, non-zero area, repeated
/// vertices removed, oriented; out.parts then holds every polygon whose rings are usable.
void cleanPolygons(const std::vector<Feature2D>& features, CheckedPolygons& out, std::vector<Diagnostic>& diagnostics,
                   PolygonCheckProgress& progress);

/// Step 2: self-intersecting and crossing rings, holes outside their exterior (those polygons
/// are dropped from out.parts) and touching or overlapping parts (out.touchingParts).
/// Changes out.parts only when it drops a polygon.
void checkPolygonContacts(const std::vector<Feature2D>& features, CheckedPolygons& out,
                          std::vector<Diagnostic>& diagnostics, PolygonCheckProgress& progress);

/// Signed area of an open ring (2 * n doubles), positive when counter-clockwise.
double ringSignedArea(const std::vector<double>& ring);
/// Length of a closed ring.
double ringLength(const std::vector<double>& ring);

/// Sorts (cell, item) entries of a uniform grid with cells in [0, cellCount): a counting sort
/// on the cell when the grid is not much larger than the list, else a plain sort. Same order
/// as std::sort when the entries come in ascending item order (as grid builders make them).
void sortGridEntries(std::vector<std::pair<long long, uint32_t>>& entries, size_t cellCount);

}  // namespace aggrelod::detail
