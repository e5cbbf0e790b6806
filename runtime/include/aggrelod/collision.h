// SPDX-License-Identifier: MIT
// aggrelod runtime, optional collision part (target aggrelod_runtime_collision, Embree 3):
// ray, segment and occlusion queries against a cut of the hierarchy chosen by distance from
// a query point or at one fixed level (docs/design.md §3). A hit reports the node and the
// original objects that node stands for. Embree stays inside collision_embree.cpp: this
// header does not include it.
#pragma once

#include <aggrelod/runtime_file.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace aggrelod::runtime {

/// Result of a ray or segment query.
struct CollisionHit {
    float distance = 0;        ///< from the ray origin / segment start, world units
    float normal[3] = {0, 0, 0};  ///< unit normal of the hit triangle, outward by its winding
    uint32_t node = kNoIndex;  ///< hierarchy node whose mesh was hit
    uint32_t triangle = 0;     ///< triangle of that node's mesh
    Span<uint32_t> objects;    ///< original objects the node stands for (view into the file)
};

/// The nodes of the hierarchy at `level`: for every root-to-leaf path, the highest node whose
/// level is <= `level`, where leaves count as finer than per-object LOD nodes and those as
/// finer than level 0. kLeafLevel gives the originals; kObjectLodLevel the coarsest
/// per-object LOD of each object (its leaf when it has none); a level k >= 0 never gives a
/// per-object LOD node (they hang below the level-0 aggregates; the walk would pass through
/// one to its leaf). Coarser versions and bundles are passed through, except the coarsest
/// bundle left of a level-k aggregate that gave way to the bundles of a group above (its
/// parent is a bundle of another level): it stands for that aggregate at level k. A root
/// bundle (the bundles of a bake's several roots) stands for none.
/// `out` is resized to the cut (node indices, increasing).
void cutAtLevel(const RuntimeFile& file, uint32_t level, std::vector<uint32_t>& out);

/// Aggregate levels present in the file (by their aggregates, or by bundles standing for them:
/// cutAtLevel), increasing (neither kLeafLevel nor kObjectLodLevel).
std::vector<uint32_t> levelsOf(const RuntimeFile& file);

/// An Embree scene over a cut: the cut's node meshes merged into one Embree geometry (rebuilt,
/// with the BVH, when the cut changes). Queries are const and may run from several threads at
/// once; changing the cut may not.
class CollisionWorld {
public:
    /// buildThreads: threads Embree may use to build (0 = all cores).
    explicit CollisionWorld(const RuntimeFile& file, unsigned buildThreads = 0);
    ~CollisionWorld();
    CollisionWorld(const CollisionWorld&) = delete;
    CollisionWorld& operator=(const CollisionWorld&) = delete;

    /// False when Embree failed (then error() says why; queries return no hit).
    bool ok() const;
    /// Last Embree error message (empty if none).
    std::string error() const;

    /// Uses exactly these nodes (indices < nodeCount; out-of-range ones are ignored).
    void useCut(const uint32_t* nodes, size_t count);
    /// Uses cutAtLevel(file, level).
    void useLevel(uint32_t level);
    /// Uses a cut that is finer near `point`: a node is used when its geometric error is at
    /// most maxErrorPerDistance * its distance to `point` (world units / world units).
    /// The cut itself is incremental (a Selector), but a changed cut rebuilds the merged mesh
    /// and the BVH (O(triangles of the cut)): call it when the agent has moved appreciably,
    /// not for every query.
    void useDistanceCut(const float point[3], float maxErrorPerDistance);
    /// Nodes of the current cut, increasing.
    const std::vector<uint32_t>& currentCut() const;

    /// Closest hit along origin + t * direction, t in [0, maxDistance] world units
    /// (direction need not be unit length; zero length gives no hit). True on a hit.
    bool raycast(const float origin[3], const float direction[3], float maxDistance, CollisionHit& hit) const;
    /// Closest hit on the segment from a to b.
    bool segment(const float a[3], const float b[3], CollisionHit& hit) const;
    /// True when anything lies on origin + t * direction, t in [0, maxDistance].
    bool occluded(const float origin[3], const float direction[3], float maxDistance) const;

    /// True when a triangle of the cut comes within `radius` (world units, >= 0) of `center`:
    /// a sphere of that radius there touches the cut's surfaces. Exact distances in double
    /// arithmetic over the candidates of an Embree point query. Does not tell whether the
    /// centre lies inside a solid: combine with raycast (first hit seen from inside).
    bool sphereTouches(const float center[3], float radius) const;
    /// True when a triangle of the cut comes within `radius` (world units, >= 0) of the
    /// segment from a to b: the capsule swept by a sphere of that radius moving from a to b
    /// touches the cut's surfaces (exact segment-triangle distances, double arithmetic).
    bool capsuleTouches(const float a[3], const float b[3], float radius) const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace aggrelod::runtime
