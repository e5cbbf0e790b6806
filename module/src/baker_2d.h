// SPDX-License-Identifier: AGPL-3.0-or-later
// The stages of one 2D bake, shared by its stage files (paper Sections 3.1-3.3; docs/design.md
// §2 in 2D): free-space ownership and models (free_space_2d.cpp, models_2d.cpp), the
// neighbourhood graph (neighbourhood_graph_2d.cpp), connection refinement
// (connection_refinement_2d.cpp) and the levels (levels_2d.cpp). Internal to the module.
#pragma once

#include "free_space_2d.h"
#include "input_vertices_2d.h"
#include "polygon_check_2d.h"
#include "stage_timer.h"

#include <aggrelod/aggregate2d.h>
#include <aggrelod/dendrogram.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace aggrelod::detail {

/// Which model each part belongs to, and which parts touch others.
struct FreeSpaceModels {
    std::vector<int> partModel;
    std::vector<char> partTouches;  // touches or overlaps a part of another feature
};

/// Which input part owns each vertex and each interior face of the triangulation.
struct FaceParts {
    std::vector<int> vertexPart;         ///< per triangulation vertex: its input vertex's part, -1 for Steiner points
    std::vector<int> facePart;           ///< per face: the part whose interior it is, -1 for free faces
    std::vector<uint8_t> faceRingEdges;  ///< per interior face: whole ring segments on its edges
};

/// Blocks of faces for the parallel passes over a triangulation (a fixed count for a given
/// size, so results do not depend on the thread count).
inline size_t faceBlockCount(size_t faceCount) { return std::clamp<size_t>(faceCount / 8192, 1, 64); }

/// Stage 3 on a triangulation of `in`: per face the winding number of the input rings (the
/// number of polygons containing it), by a flood from the outside of the hull that counts
/// the rings along each constrained edge it crosses.
std::vector<int> windingNumbers(const InputVertices& in, const Triangulation2D& tri, int threadCount);

/// Free-space ownership: the part of each vertex and of each face inside a polygon
/// (winding >= 1).
FaceParts assignFaceParts(const InputVertices& in, const Triangulation2D& tri, const std::vector<int>& winding,
                          int threadCount);

/// Stage 4: models (parts of one feature, touching, overlapping or nested parts joined), the
/// model of every vertex and interior face, and (unless graphOnly) each corner's model and
/// the polygons of the models whose boundary is exactly their rings; with withModelPoints
/// also every model's ring vertices.
void buildModels2D(const InputVertices& in, const CheckedPolygons& checked, const std::vector<int>& winding,
                   const FaceParts& faces, FreeSpace2D& space, FreeSpaceModels& models, bool graphOnly,
                   bool withModelPoints, int threadCount);

/// Voids (unless graphOnly): free faces enclosed by one model (input holes, gaps closed by
/// touching polygons), which no level fills.
void markVoids(const CheckedPolygons& checked, FreeSpace2D& space, bool graphOnly);

/// Stage 5: the neighbourhood graph on the models of `space`: every face's area and edge
/// lengths, and per model pair its shortest connection; unless graphOnly also each pair's
/// edge lengths with their running sums, and each free edge's pair.
void buildNeighbourhoodGraph2D(FreeSpace2D& space, bool graphOnly, int threadCount);

/// Stages 3-5 given the winding numbers: ownership, models, voids, graph.
/// graphOnly: only what the dendrogram and the Steiner points need (models, pairs with their
/// shortest connection, edge lengths); no voids, per-pair length statistics, edge pairs or
/// model points (the pass before the Steiner points, whose result is replaced).
/// withModelPoints: fill space.modelPoints (read only by the convex hulls).
void buildFreeSpace(const InputVertices& in, const CheckedPolygons& checked, const std::vector<int>& winding,
                    FreeSpace2D& space, FreeSpaceModels& models, bool graphOnly, int threadCount,
                    bool withModelPoints = false);

/// The graph's weights in 2D: the shortest connection of each pair.
std::vector<GraphEdge> weighedGraph(const FreeSpace2D& space);

/// Connection refinement (docs/design.md §2.4 step 4) after the graph-only pass: Steiner
/// points at the shortest connections of the dendrogram's merges are inserted into the
/// triangulation, then the free space and graph are built again in full (out.merges and
/// mergePair with them). Times its stages on `timer`. False, with `error`, when the points
/// could not be inserted.
bool refineConnections2D(const CheckedPolygons& checked, InputVertices& in, std::vector<int>& winding,
                         FreeSpace2D& space, FreeSpaceModels& models, std::vector<uint32_t>& mergePair,
                         bool needHulls, int threadCount, StageTimer& timer, Hierarchy2D& out, std::string& error);

/// The levels (paper Algorithm 1): thresholds, then every level sculpted in parallel with its
/// polygons, measures and baselines, into out.levels. Times the stage on `timer`.
void buildLevels2D(const std::vector<Feature2D>& features, const Settings2D& settings, const FreeSpace2D& space,
                   const std::vector<uint32_t>& mergePair, bool needHulls, StageTimer& timer, Hierarchy2D& out);

}  // namespace aggrelod::detail
