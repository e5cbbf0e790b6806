// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod module (internal): the proxy error measurement of proxy_error.cpp with the
// originals' search structures prepared once by the caller (hierarchy_nodes.cpp prepares
// each object once and reuses it for every node and level holding it, instead of merging
// the originals and rebuilding a BVH over them per node).
#pragma once

#include "mesh_distance.h"

#include <aggrelod/hierarchy_nodes.h>

#include <cmath>
#include <vector>

namespace aggrelod::detail {

/// Flat patches of a mesh whose projection along their normal is a convex polygon tiled by
/// their triangles once (no holes or folds): regions of a proxy or an original that
/// straddle several of its triangles get a bound near 0 when they lie on the patch, however
/// the triangulations differ (proxy_error.cpp, patchBound).
struct PlanarPatches {
    struct Patch {
        double normal[3];          ///< unit normal (of the seed triangle)
        const double* origin;      ///< a vertex; heights are measured from it along normal
        double hmin, hmax;         ///< range of the patch vertices' heights (contains 0)
        double slack;              ///< the polygon lies within this distance of the patch (in projection)
        uint32_t loopBegin, loopEnd;  ///< polygon corners (counter-clockwise about normal) in loops
    };
    std::vector<uint32_t> patchOf;  ///< per triangle: patch index, ~0u for none
    std::vector<Patch> patches;
    std::vector<const double*> loops;  ///< pointers into the mesh positions
};

/// Patches grown from each triangle in index order across edges (trianglesAcrossEdges)
/// while the triangles stay within a rounding allowance (1e-6 of the mesh's extent plus
/// largest coordinate) of the seed's plane; kept when the patch projects to a convex polygon.
PlanarPatches planarPatches(const double* positions, const uint32_t* indices, const uint32_t* across,
                            size_t triangleCount);

/// One original object ready for measureProxyErrorPrepared: a BVH of its triangles and,
/// per triangle edge k (corners k -> k+1), the triangle across it (edges matched by vertex
/// position; the lowest other triangle on a non-manifold edge; ~0u on a border).
struct PreparedOriginal {
    const InputObject* object = nullptr;
    TriangleBvh bvh;
    std::vector<uint32_t> across;  ///< 3 * triangleCount
    PlanarPatches patches;
};

/// Fills `out` for `object` (kept by pointer: must outlive `out`). Throws
/// std::invalid_argument for a non-finite coordinate or an index out of range.
void prepareOriginal(const InputObject& object, PreparedOriginal& out);

/// Per triangle edge k (corners k -> k+1) the triangle across it, as in PreparedOriginal.
/// positions: 3 * vertexCount; indices: 3 * triangleCount (each < vertexCount).
std::vector<uint32_t> trianglesAcrossEdges(const double* positions, const uint32_t* indices, size_t triangleCount);

struct ProxyMeasureOptions {
    /// The proxy is known to enclose its originals up to enclosureSlack (world units: e.g.
    /// an enclosure built in doubles whose vertices were then rounded to floats moves no
    /// surface point farther than the largest rounding). originals -> proxy is then that
    /// slack, not measured.
    bool enclosesOriginals = false;
    double enclosureSlack = 0;
    /// Stop refining once a distance above this is found (world units): the caller only
    /// needs to know the error is over it. Bounds stay valid; the other direction is not
    /// measured then (its bound is enclosureSlack, or infinite for a proxy not known to
    /// enclose).
    double giveUpAbove = INFINITY;
};

/// measureProxyError against prepared originals (same results as the public function,
/// which prepares them itself).
ProxyError measureProxyErrorPrepared(const std::vector<float>& proxyPositions,
                                     const std::vector<uint32_t>& proxyIndices,
                                     const std::vector<const PreparedOriginal*>& originals, double tolerance,
                                     size_t maxRefinementsPerDirection);
/// The same with options (ProxyMeasureOptions).
ProxyError measureProxyErrorPrepared(const std::vector<float>& proxyPositions,
                                     const std::vector<uint32_t>& proxyIndices,
                                     const std::vector<const PreparedOriginal*>& originals, double tolerance,
                                     size_t maxRefinementsPerDirection, const ProxyMeasureOptions& options);

}  // namespace aggrelod::detail
