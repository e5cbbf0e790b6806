// SPDX-License-Identifier: AGPL-3.0-or-later
// Steiner points on the constrained edges of a flat 2D constrained Delaunay triangulation
// (docs/design.md §2.4 step 4): the points the 2D pipeline adds at the shortest connection of every
// merge, inserted into the exported triangulation instead of into CGAL's, so that the
// triangulation is neither rebuilt nor exported twice. Also the canonical numbering that
// every exported triangulation gets.
#pragma once

#include "cdt_2d.h"

#include <cstdint>
#include <vector>

namespace aggrelod::detail {

/// Puts the faces of `tri` in canonical order, so that the numbering depends only on the
/// triangulation, not on how it was built: each face's corners rotated to start at its
/// smallest vertex (still counter-clockwise; neighbors and constrained rotate along), faces
/// sorted by their sorted vertex triple, neighbour indices renumbered. threadCount: 0 = all
/// cores; the result is the same for every count.
void canonicalizeFaces2D(Triangulation2D& tri, int threadCount);

/// Inserts the points of every split into `tri` (as build() exported it: vertexInput and
/// inputVertex refer to build()'s input), each on the constrained edge from input point
/// split.from to split.to, which becomes the constrained chain from -> points -> to.
/// The triangulation stays constrained Delaunay: each point splits the edge's two faces
/// (2 -> 4; on the convex hull, the faces CGAL would make) and Lawson flips with CGAL's
/// in-circle test and its symbolic perturbation restore the Delaunay property, so the result
/// is the triangulation CGAL builds for the same points and constraints. A point a rounding
/// error off its segment is kept where it is: the chain bends by that error, as in CGAL.
/// Only a segment that is still one constrained edge is split (not one already split by
/// another ring's vertex); its points go in in order, and a point that would make a flat or
/// inverted triangle (next to a sliver), or whose rounding error would make CGAL triangulate
/// around it otherwise, ends that split. appliedCount[k]: how many points of
/// splits[k] went in (a prefix). firstVertex[k]: the vertex of its first point; the others
/// follow, consecutive. New vertices are appended with vertexInput -1; faces are changed in
/// place or appended: call renumberAfterSplits2D() before reading the result.
/// faceWinding (optional, one per face): winding numbers of the input rings, or any label
/// that changes only across constrained edges; kept up to date (the pieces of a split face
/// keep its value, a flip keeps its faces' common value, the thin face on a hull edge lies
/// outside every ring: 0), so they need not be computed again.
void insertSplitPoints2D(Triangulation2D& tri, const std::vector<ConstraintSplit>& splits,
                         std::vector<uint32_t>& appliedCount, std::vector<int>& firstVertex,
                         std::vector<int>* faceWinding = nullptr);

/// Vertex numbering after insertSplitPoints2D(), as the export numbers vertices: build()
/// input point i becomes input point newInputIndex[i], point j of splits[k] input point
/// splitFirstIndex[k] + j (j < appliedCount[k]); vertices are numbered by their smallest
/// input point, the intersection vertices CGAL made (vertexInput -1) after them in their old
/// order. Faces keep their order (the insertion is deterministic, so that order is too);
/// canonicalizeFaces2D() gives the order a fresh export would have. inputCount: the size of
/// the new input.
void renumberAfterSplits2D(Triangulation2D& tri, const std::vector<size_t>& newInputIndex,
                           const std::vector<long long>& splitFirstIndex, const std::vector<uint32_t>& appliedCount,
                           const std::vector<int>& firstVertex, size_t inputCount);

}  // namespace aggrelod::detail
