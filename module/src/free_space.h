// SPDX-License-Identifier: AGPL-3.0-or-later
// The tetrahedralized scene shared by every level (docs/design.md §2.1 and §2.2): which model owns
// each vertex, which tets are free space, and the per-pair statistics of the neighbourhood
// graph. Built once per bake; levels only read it.
#pragma once

#include "neighbourhood_graph.h"
#include "tetgen_backend.h"

#include <cstdint>
#include <vector>

namespace aggrelod::detail {

/// One neighbourhood-graph edge in 3D: the shared pair record (models, edge lengths) and the
/// distances that can weigh it.
struct ModelPair : GraphPair {
    double shortestEdge = 0;        ///< the paper's weight (cdt distance)
    int shortestEdgeVertexA = -1;   ///< its endpoint on a (tet mesh vertex)
    int shortestEdgeVertexB = -1;   ///< its endpoint on b
    double exactDistance = 0;       ///< exact mesh-to-mesh minimum distance
    double closestA[3] = {0, 0, 0}; ///< closest point on a
    double closestB[3] = {0, 0, 0}; ///< closest point on b
    uint32_t closestTriangleA = ~0u; ///< triangle of a's surface holding closestA (~0u: unknown)
    uint32_t closestTriangleB = ~0u;
    double weight = 0;              ///< the one used for grouping (exact or cdt)
};

struct FreeSpace {
    TetMesh mesh;
    std::vector<int> vertexModel;   ///< per mesh vertex: owning model, -1 for Steiner points
    std::vector<int> tetModel;      ///< per tet: -1 free space, else the model it lies inside
    std::vector<double> tetVolume;  ///< per tet, units^3 (positive)
    std::vector<ModelPair> pairs;   ///< sorted by (a, b)
    std::vector<double> tetEdgeLength; ///< 6 per tet (corner pairs 01 02 03 12 13 23), units
    std::vector<int> tetEdgePair;      ///< 6 per tet: index into pairs, or kSameModelEdge / kUnpairedEdge
    std::vector<std::vector<int>> surfaceTetsOfModel; ///< per model: free tets with a facet on its surface, ascending
    /// Per tet: for an object tet, bit j is set when the neighbour across face j lies outside
    /// its model (free space or the hull); 0 for free tets. Only those faces of an object
    /// tet can ever be on an aggregate's surface, so scans skip object interiors.
    std::vector<uint8_t> objectFaceMask;
    size_t modelCount = 0;
    PairEdgeLengths edgeLengths;    ///< per pair: its free-space edge lengths (see GraphPair)
};

}  // namespace aggrelod::detail
