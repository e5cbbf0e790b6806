// SPDX-License-Identifier: AGPL-3.0-or-later
// The triangulated free space of a 2D scene, shared by the graph, hierarchy and sculpting
// stages (docs/design.md §2.1–2.4, 2D). Built once; every level only reads it.
#pragma once

#include "cdt_2d.h"

#include <aggrelod/aggregate2d.h>

#include <cstdint>
#include <vector>

namespace aggrelod::detail {

constexpr int kSameModelEdge2D = -1;  ///< edgePair: both ends on one model
constexpr int kUnpairedEdge2D = -2;   ///< edgePair: an end is a Steiner point

/// Statistics of one model pair joined by free-space triangulation edges.
struct ModelPair2D {
    uint32_t a = 0, b = 0;             ///< models, a < b
    double minDistance = 0;            ///< shortest connection (graph weight), world units
    int bestFace[2] = {-1, -1};        ///< free faces holding the shortest connection
    int connection[3] = {-1, -1, -1};  ///< its ends: vertices (c0, c1), or vertex c0 to the edge (c1, c2)
    uint32_t firstLength = 0, lengthCount = 0;  ///< FreeSpace2D::pairLengths[firstLength, + lengthCount)
    uint32_t firstPrefix = 0;          ///< FreeSpace2D::pairPrefixSum(Squares)[firstPrefix, + lengthCount + 1)
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
    std::vector<int> edgePair;       ///< 3 * faceCount: index into pairs, or kSameModelEdge2D / kUnpairedEdge2D
    std::vector<ModelPair2D> pairs;  ///< sorted by (a, b)
    std::vector<double> pairLengths;           ///< per pair: lengths of the free edges joining a and b, ascending
    std::vector<double> pairPrefixSum;         ///< per pair: running sums of its lengths, from 0
    std::vector<double> pairPrefixSumSquares;  ///< per pair: running sums of its squared lengths, from 0
    std::vector<std::vector<double>> modelPoints;  ///< per model: all its ring vertices (x y pairs); only when hulls are needed
    /// Per model whose boundary in the triangulation is exactly its input rings (no touching or
    /// overlapping polygon, no vertex shared with another ring): its polygons as the polygon
    /// extraction traces them (rings with their Steiner points, each from its first vertex;
    /// parts and holes in input order). Empty for the other models. A group of such a model
    /// alone, with no kept free face, is exactly these polygons.
    std::vector<std::vector<Polygon2D>> modelPolygons;

};

}  // namespace aggrelod::detail
