// SPDX-License-Identifier: AGPL-3.0-or-later
// The triangulated free space of a 2D scene, shared by the graph, hierarchy and sculpting
// stages (docs/design.md §2.1–2.4, 2D). Built once; every level only reads it.
#pragma once

#include "cdt_2d.h"
#include "neighbourhood_graph.h"

#include <aggrelod/aggregate2d.h>

#include <cstdint>
#include <vector>

namespace aggrelod::detail {

/// One neighbourhood-graph edge in 2D: the shared pair record (models, edge lengths) and its
/// shortest connection.
struct ModelPair2D : GraphPair {
    double minDistance = 0;            ///< shortest connection (graph weight), world units
    int bestFace[2] = {-1, -1};        ///< free faces holding the shortest connection
    int connection[3] = {-1, -1, -1};  ///< its ends: vertices (c0, c1), or vertex c0 to the edge (c1, c2)
};

struct FreeSpace2D {
    Triangulation2D tri;
    size_t modelCount = 0;
    std::vector<int> vertexModel;    ///< per vertex: owning model, -1 for Steiner points
    std::vector<int> faceModel;      ///< per face: model whose interior it is, -1 for free space
    std::vector<int> cornerModel;    ///< 3 * faceCount: vertexModel of each corner (read by every level)
    std::vector<char> faceVoid;      ///< per face: free, enclosed by one model (an input hole): never filled
    std::vector<double> faceArea;    ///< per face
    std::vector<double> edgeLength;  ///< 3 * faceCount: edge opposite corner i
    std::vector<double> faceLongest; ///< per face: its longest edge
    std::vector<int> edgePair;       ///< 3 * faceCount: index into pairs, or kSameModelEdge / kUnpairedEdge
    std::vector<ModelPair2D> pairs;  ///< sorted by (a, b)
    PairEdgeLengths edgeLengths;     ///< per pair: its free-space edge lengths (see GraphPair)
    std::vector<std::vector<double>> modelPoints;  ///< per model: all its ring vertices (x y pairs); only when hulls are needed
    /// Per model whose boundary in the triangulation is exactly its input rings (no touching or
    /// overlapping polygon, no vertex shared with another ring): its polygons as the polygon
    /// extraction traces them (rings with their Steiner points, each from its first vertex;
    /// parts and holes in input order). Empty for the other models. A group of such a model
    /// alone, with no kept free face, is exactly these polygons.
    std::vector<std::vector<Polygon2D>> modelPolygons;

};

}  // namespace aggrelod::detail
