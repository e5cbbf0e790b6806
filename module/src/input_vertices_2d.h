// SPDX-License-Identifier: AGPL-3.0-or-later
// The input rings of a 2D scene as one vertex array (docs/design.md §2.1 in 2D): what the
// constrained triangulation is built from, with each ring's structure (to orient its
// constraints), a grid of its segments (to find the rings under a triangulation edge) and,
// after connection refinement, the Steiner points on its segments.
#pragma once

#include "cdt_2d.h"
#include "polygon_check_2d.h"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace aggrelod::detail {

/// Input vertices as one array, with the ring structure needed to orient constraints.
struct InputVertices {
    std::vector<double> points;            // 2 * n
    std::vector<uint32_t> part;            // per vertex
    std::vector<uint32_t> ringStart, ringSize;  // per vertex: its ring's first vertex and size
    std::vector<std::pair<size_t, size_t>> segments;
    std::vector<char> shared;              // per vertex: another input vertex lies at the same place (setShared)
    std::vector<char> partTouches;         // per part: its boundary meets another part's
    // Uniform grid of the ring segments (segment i starts at vertex i), for finding the input
    // segments under a triangulation edge; segments spanning many cells go to `longSegments`.
    double gridX0 = 0, gridY0 = 0, gridCell = 1;
    long long gridNx = 1, gridNy = 1;
    std::vector<std::pair<long long, uint32_t>> gridEntries;  // (cell, segment), sorted
    std::vector<uint32_t> longSegments;

    size_t next(size_t v) const { return ringStart[v] + (v - ringStart[v] + 1) % ringSize[v]; }
    long long cellX(double px) const {
        return std::clamp<long long>(static_cast<long long>((px - gridX0) / gridCell), 0, gridNx - 1);
    }
    long long cellY(double py) const {
        return std::clamp<long long>(static_cast<long long>((py - gridY0) / gridCell), 0, gridNy - 1);
    }
    size_t prev(size_t v) const { return ringStart[v] + (v - ringStart[v] + ringSize[v] - 1) % ringSize[v]; }
    double x(size_t v) const { return points[2 * v]; }
    double y(size_t v) const { return points[2 * v + 1]; }
};

/// Steiner points on the ring segments, flat: the segment starting at original input vertex s
/// gets an extra (collinear) vertex at each parameter of t[first[s], first[s] + count[s]),
/// ascending, in (0, 1).
struct SegmentSplits {
    std::vector<uint32_t> first, count;
    std::vector<double> t;
    size_t size(size_t s) const { return s < count.size() ? count[s] : 0; }
    const double* at(size_t s) const { return t.data() + first[s]; }
};

/// Builds in's segment grid (gridX0 ... longSegments) from its points and rings.
void buildSegmentGrid(InputVertices& in);

/// in.partTouches from checked.touchingParts.
void markTouchingParts(InputVertices& in, const CheckedPolygons& checked);

/// in.shared from the triangulation of `in`: input points sharing a vertex lie at the same place.
void setShared(InputVertices& in, const Triangulation2D& tri);

/// Input vertices of the checked polygons (in.shared is set by setShared), with the Steiner
/// points of `splits` (optional) after their segment's start.
InputVertices inputVertices(const CheckedPolygons& checked, const SegmentSplits* splits, bool withGrid = true);

}  // namespace aggrelod::detail
