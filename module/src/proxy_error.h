// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod module (internal): the proxy error measurement of proxy_error.cpp with the
// originals' search structures prepared once by the caller (hierarchy_nodes.cpp prepares
// each object once and reuses it for every node and level holding it, instead of merging
// the originals and rebuilding a BVH over them per node).
#pragma once

#include "mesh_distance.h"

#include <aggrelod/hierarchy_nodes.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <unordered_map>
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
    /// A closed surface of one shell, convex at every edge and every vertex (so the boundary
    /// of a convex solid K, by Tietze's theorem on locally convex sets): the distance to K is
    /// a convex function, so over a proxy triangle outside K it is largest at a corner.
    bool convexSolid = false;
    /// How far (world units) a vertex lies in front of a neighbouring face's plane, at most,
    /// in an object that counts as convex (float rounding of flat faces split into many
    /// triangles; at most 1e-6 of the largest coordinate). Added twice to bounds that use
    /// convexity.
    double convexSlack = 0;
};

/// Fills `out` for `object` (kept by pointer: must outlive `out`). Throws
/// std::invalid_argument for a non-finite coordinate or an index out of range.
void prepareOriginal(const InputObject& object, PreparedOriginal& out);

/// Per triangle edge k (corners k -> k+1) the triangle across it, as in PreparedOriginal.
/// positions: 3 * vertexCount; indices: 3 * triangleCount (each < vertexCount).
std::vector<uint32_t> trianglesAcrossEdges(const double* positions, const uint32_t* indices, size_t triangleCount);

/// Certified proxy -> originals bounds of single proxy triangles, kept across measurements of
/// several proxies of the same originals (the versions of one object or aggregate share many
/// triangles): a triangle found here is not measured again. A bound is valid whatever the
/// tolerance of the measurement that made it; only looser or tighter. Lookups only (never
/// iterated), so results do not depend on the map's order.
struct TriangleBoundCache {
    using Key = std::array<float, 9>;  ///< corners, sorted lexicographically
    struct Bound {
        double upper = 0;  ///< every point of the triangle is this close to an original surface
        double lower = 0;  ///< a point of the triangle is this far from them
    };
    struct Hash {
        size_t operator()(const Key& k) const {
            uint64_t h = 1469598103934665603ull;
            for (float x : k) {
                uint32_t bits;
                std::memcpy(&bits, &x, sizeof bits);
                h = (h ^ bits) * 1099511628211ull;
            }
            return size_t(h);
        }
    };
    static Key key(const float* a, const float* b, const float* c) {
        std::array<const float*, 3> p{a, b, c};
        std::sort(p.begin(), p.end(), [](const float* x, const float* y) { return std::lexicographical_compare(x, x + 3, y, y + 3); });
        Key k;
        for (int v = 0; v < 3; ++v)
            for (int d = 0; d < 3; ++d) k[size_t(3 * v + d)] = p[size_t(v)][d] + 0.0f;  // -0 as +0: one hash per value
        return k;
    }
    std::unordered_map<Key, Bound, Hash> bounds;
    /// Enters the triangles of `object` whose corners are floats exactly (as read from glTF)
    /// with bound 0: a proxy triangle equal to one lies on the original surface.
    void addOriginal(const InputObject& object);
};

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
    /// Optional: per-triangle proxy -> originals bounds to reuse and to fill (same originals
    /// at every use).
    TriangleBoundCache* cache = nullptr;
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
