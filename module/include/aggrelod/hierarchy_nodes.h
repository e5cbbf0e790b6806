// aggrelod module: the hierarchy of a 3D bake as a tree of nodes for real-time use
// (DESIGN sections 2.5 and 2.6).
//
// Leaves are the original objects (geometric error 0). Inner nodes are the aggregates of
// the levels of a Hierarchy3D; the parent of an aggregate is the aggregate that contains
// its objects at the next coarser level. An aggregate that does not change from one level
// to the next (same objects, same solid: same vertices, volume and area, whatever the
// triangulation of flat faces) is one node spanning those levels. Every
// aggregate gets a proxy simplified with meshoptimizer (target error a fraction of the
// level's delta) and its measured geometric error against the original objects.
//
// Units: every length is in world units (those of the input objects).
// Determinism: the same Hierarchy3D, objects and settings give bit-identical nodes,
// whatever the thread count.
#pragma once

#include <aggrelod/aggregate3d.h>

#include <cstdint>
#include <string>
#include <vector>

namespace aggrelod {

constexpr uint32_t kNoNode = 0xFFFFFFFFu;

struct ProxySettings {
    /// meshoptimizer's target error for the proxy of a level-k aggregate, as a fraction of
    /// delta_k (world units once multiplied). 0 keeps the exact aggregate as its proxy.
    double simplifyFraction = 0.25;
    /// Spacing of the error samples (world units) as a fraction of delta_k ...
    double sampleSpacingFraction = 0.02;
    /// ... widened so that one direction of one proxy takes at most about this many samples.
    size_t maxSamplesPerDirection = 20000;
    int threadCount = 0;  ///< 0 = hardware concurrency; results identical for every count
    ProgressCallback progress;  ///< optional, stage "proxies"; called from the calling thread only
};

/// One-sided sampled distances between a proxy and the original objects it stands for.
struct ProxyError {
    double proxyToOriginals = 0;  ///< max over proxy samples of the distance to the originals' surfaces
    double originalsToProxy = 0;  ///< max over original samples of the distance to the proxy solid
                                  ///<   (0 for a sample inside the proxy: it is covered)
    double sampleSpacing = 0;     ///< every surface point lies within this distance of a sample
    size_t sampleCount = 0;       ///< both directions together
    /// Upper bound of both one-sided Hausdorff distances: the distance functions are
    /// 1-Lipschitz, so the true maximum is at most the sampled one + sampleSpacing.
    double bound() const;
};

struct HierarchyNode {
    uint32_t parent = kNoNode;         ///< index in HierarchyNodes::nodes; kNoNode for roots
    std::vector<uint32_t> children;    ///< node indices, ascending (all smaller than this node's)
    std::vector<uint32_t> sources;     ///< original object indices, ascending
    bool leaf = false;                 ///< an original object (node index = object index)
    int firstLevel = -1;               ///< levels [firstLevel, lastLevel] of the Hierarchy3D
    int lastLevel = -1;                ///<   this aggregate stands for; -1 for leaves
    uint32_t aggregateIndex = 0;       ///< index in levels[firstLevel].aggregates (aggregates only)
    double delta = 0;                  ///< delta of firstLevel, world units (0 for leaves)
    std::vector<float> positions;      ///< proxy (leaf: the original), 3 * vertexCount, world units
    std::vector<uint32_t> indices;     ///< 3 * triangleCount, outward
    size_t exactTriangleCount = 0;     ///< triangles of the unsimplified aggregate (leaf: of the object)
    ProxyError error;                  ///< measured error of this node's proxy (zeros for leaves)
    /// Stored geometric error, world units: max(error.bound(), every child's geometricError),
    /// so it never decreases towards the roots. Exactly representable as a float (rounded up).
    double geometricError = 0;
    /// Axis-aligned box containing the proxy and every child's box; float-representable,
    /// rounded outwards.
    double boundsMin[3] = {0, 0, 0}, boundsMax[3] = {0, 0, 0};
    /// Sphere containing the proxy and every child's sphere; centre float-representable,
    /// radius rounded up so that the nesting holds when read back as floats.
    double sphereCenter[3] = {0, 0, 0};
    double sphereRadius = 0;
};

struct HierarchyNodes {
    /// Leaves first (node i = object i for i < objectCount), then the aggregate nodes by
    /// firstLevel and aggregate index. Children always come before their parent.
    std::vector<HierarchyNode> nodes;
    std::vector<uint32_t> roots;       ///< ascending
    size_t objectCount = 0;
    /// nodeOfAggregate[k][g]: node standing for levels[k].aggregates[g].
    std::vector<std::vector<uint32_t>> nodeOfAggregate;
};

/// Builds the node tree of `hierarchy`, baked from `objects` (same array, same order).
/// Returns false with a message in `error` when the two do not match (a source index out of
/// range, an object in no or in two aggregates of one level, a level not coarser than the
/// previous one). Never throws for such input.
bool buildHierarchyNodes(const Hierarchy3D& hierarchy, const std::vector<InputObject>& objects,
                         const ProxySettings& settings, HierarchyNodes& out, std::string& error);

/// Measures the error of `proxy` (float positions, 3 * vertexCount; indices 3 * triangleCount)
/// against `originals` (closed meshes, world units) with sample spacing about `spacing`,
/// widened to keep each direction under maxSamplesPerDirection. Deterministic, single thread.
ProxyError measureProxyError(const std::vector<float>& proxyPositions,
                             const std::vector<uint32_t>& proxyIndices,
                             const std::vector<const InputObject*>& originals, double spacing,
                             size_t maxSamplesPerDirection);

}  // namespace aggrelod
