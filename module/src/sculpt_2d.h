// Sculpting one 2D level (DESIGN 2.4; paper Section 3.3) and turning the kept triangles
// into OGC-valid polygons with holes.
#pragma once

#include "free_space_2d.h"

#include <vector>

namespace aggrelod::detail {

/// F of every model pair at one level (DESIGN 2.4 step 3), evaluated once per level.
struct EdgeLimits2D {
    double sameModel = 0;      ///< F for an edge with both ends on one model
    double unpaired = 0;       ///< F for an edge with a Steiner end
    double delta = 0;          ///< the level threshold
    std::vector<double> pair;  ///< per FreeSpace2D::pairs entry
};

EdgeLimits2D computeEdgeLimits2D(const FreeSpace2D& space, double delta, const AggregateFunction& function);

/// Labels every face with the group whose aggregate contains it (-1: in none).
/// `joinedPairs`: indices into space.pairs of the merges of this level, whose shortest
/// connection is kept (DESIGN 2.4 step 4).
void sculptLevel2D(const FreeSpace2D& space, const std::vector<uint32_t>& modelGroup, const EdgeLimits2D& limits,
                   const std::vector<int>& joinedPairs, std::vector<int>& faceLabel);

/// Total area and boundary length of the labelled faces (all groups).
Measures2D measureLabels2D(const FreeSpace2D& space, const std::vector<int>& faceLabel);

/// Polygons with holes of every group: aggregates[g].polygons (exterior CCW, holes CW,
/// parts touching at a point split apart) and aggregates[g].measures.
void extractPolygons2D(const FreeSpace2D& space, const std::vector<int>& faceLabel, size_t groupCount,
                       std::vector<Aggregate2D>& aggregates);

/// Convex hull (counter-clockwise, open ring) of x y pairs; Andrew's monotone chain.
std::vector<double> convexHull2D(std::vector<double> points);

}  // namespace aggrelod::detail
