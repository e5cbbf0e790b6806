// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod module (internal): simplification that keeps a closed mesh enclosing its input
// (docs/design.md §2.6), for proxies that collide conservatively.
#pragma once

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace aggrelod::detail {

struct ConservativeSimplifyResult {
    size_t collapses = 0;      ///< edge collapses done
    /// Largest accumulated estimate of how far the output lies outside the input (world
    /// units): an estimate that orders and stops the collapses, not a certified bound.
    double errorEstimate = 0;
};

/// Simplifies a closed, edge-manifold, outward-oriented triangle mesh by edge collapses
/// whose new vertex lies on or outside the plane of every face around the collapsed edge,
/// so that every intermediate mesh (and the output) encloses the input (progressive hulls).
/// Collapses run cheapest first while their accumulated estimate stays <= maxError (world
/// units) and the mesh has more than minTriangles triangles. Collapses that would make the
/// mesh non-manifold, fold a face over (normal turned by more than ~70 degrees), fold two
/// neighbouring faces onto each other (normals within ~2.6 degrees of opposite) or reduce a
/// shell below a tetrahedron are skipped, and so are collapses that would give a vertex
/// more than 24 neighbours (flat regions would otherwise become fans, whose cost grows with
/// every collapse near them); vertices that share their position with another
/// vertex (a solid touching itself at a point or edge) never move.
/// positions: 3 * vertexCount doubles; indices: 3 * triangleCount, each < vertexCount.
/// Output: the used vertices only, numbered by first use. Deterministic, single thread.
/// The output can intersect itself where the surface faces itself across a gap narrower
/// than about 2 * maxError: check with meshSelfIntersects.
ConservativeSimplifyResult simplifyConservative(const std::vector<double>& positions,
                                                const std::vector<uint32_t>& indices, double maxError,
                                                size_t minTriangles, std::vector<double>& outPositions,
                                                std::vector<uint32_t>& outIndices);

struct ConservativeSnapshot {
    std::vector<double> positions;  ///< 3 * vertexCount
    std::vector<uint32_t> indices;  ///< 3 * triangleCount
    double errorEstimate = 0;       ///< as ConservativeSimplifyResult::errorEstimate
};

/// The same simplification taken on through ascending maxErrors (world units), with a
/// snapshot of the mesh at each: out[i] is what simplifyConservative would give for
/// maxErrors[i], each one enclosing the previous one. One pass for the whole series.
ConservativeSimplifyResult simplifyConservativeSeries(const std::vector<double>& positions,
                                                      const std::vector<uint32_t>& indices,
                                                      const std::vector<double>& maxErrors, size_t minTriangles,
                                                      std::vector<ConservativeSnapshot>& out);

/// simplifyConservative to maxError, made again with the corners of crossing faces pinned
/// (never moved) until the output does not intersect itself, at most maxRounds times (each
/// round is a whole simplification). pinned: per input vertex, 1 = never moves; grown by the
/// rounds (pass it on to a finer maxError of the same mesh). rounds (optional): set to the
/// rounds made. Returns false when the last round still intersects itself (out holds it),
/// or maxRounds <= 0. positions, indices as simplifyConservative.
bool simplifyConservativeClean(const std::vector<double>& positions, const std::vector<uint32_t>& indices,
                               double maxError, std::vector<char>& pinned, int maxRounds, ConservativeSnapshot& out,
                               int* rounds = nullptr);

/// Pairs (lower, higher triangle index) of triangles that share no vertex position and
/// intersect or touch, at most maxPairs of them, in traversal order. Deterministic.
std::vector<std::pair<uint32_t, uint32_t>> selfIntersectingTriangles(const std::vector<double>& positions,
                                                                     const std::vector<uint32_t>& indices, size_t maxPairs);

/// True when two triangles of the mesh that share no vertex position intersect or touch.
/// positions: 3 * vertexCount doubles; indices: 3 * triangleCount. Deterministic.
bool meshSelfIntersects(const std::vector<double>& positions, const std::vector<uint32_t>& indices);

}  // namespace aggrelod::detail
