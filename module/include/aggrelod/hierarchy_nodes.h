// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod module: the hierarchy of a 3D bake as a tree of nodes for real-time use
// (docs/design.md §2.5 and §2.6).
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
#include <aggrelod/tile_cache.h>

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace aggrelod {

constexpr uint32_t kNoNode = 0xFFFFFFFFu;

struct ProxySettings {
    /// Room the proxy of a level-k aggregate gets for simplification, as a fraction of
    /// delta_k (world units once multiplied): its error budget is the certified error of the
    /// exact aggregate (the fill's own distance to the originals, which nothing enclosing
    /// the aggregate can undercut) plus this. The proxy is the coarsest enclosing
    /// simplification whose certified error fits the budget. 0 keeps the exact aggregate.
    double simplifyFraction = 0.25;
    /// Most simplified versions of one object (per-object LOD) between its leaf and its first
    /// aggregate with other objects: enclosing simplifications at error targets sqrt(2)
    /// apart from a thousandth of the object's diagonal up to that aggregate's error. They
    /// stand in for the aggregates of the object alone. 0 = none (those aggregates stay).
    int objectLodCount = 16;
    /// Most coarser versions of one aggregate between it and its parent: enclosing
    /// simplifications of its proxy at error targets sqrt(2) apart from its budget up to its
    /// parent's error (a root: up to its diagonal). 0 = none.
    int coarserCount = 16;
    /// Most bundles below one aggregate of several objects: its children's drawn versions
    /// merged into one mesh (the lightest version of each child within a threshold), at
    /// thresholds between the children's errors and the aggregate's, so that a distant group
    /// costs one draw call. Each kept bundle has at most 9/10 of the triangles of the finer
    /// one, or holds more children: a child whose versions all have errors above the finest
    /// threshold (an aggregate with a wide fill) joins the first bundle whose threshold
    /// reaches its finest version, and stays apart below it. 0 = none.
    int bundleCount = 16;
    /// Lowest bundle threshold as a fraction of the diagonal of the aggregate's objects (the
    /// finest bundle sits there, or higher where fewer than two children have versions that
    /// fine): the children's versions that bundles replace are those drawn only where one
    /// pixel is at least this fraction of the group's size, far enough for one error over the
    /// whole group to cost about what one per child would.
    double bundleMinErrorFraction = 1.0 / 128;
    /// Most triangles of one bundle (a larger merged mesh is not made).
    size_t bundleMaxTriangles = 65536;
    /// Most vertices of the few-faced convex polytopes that enclose a one-shell proxy's
    /// convex hull (intersections of its supporting half-spaces), tried beside the enclosing
    /// simplifications for per-object LOD levels and coarser versions: they reach down to a
    /// tetrahedron where edge collapses stop. 0 = not tried.
    int polytopeVertices = 24;
    /// How far (world units, as a fraction of delta_k) the certified upper bound of the
    /// error may exceed the largest distance actually found; the refinement stops there ...
    double toleranceFraction = 0.02;
    /// ... or when a direction has evaluated this many regions beyond one per triangle of
    /// the measured side (proxy triangles one way, original triangles the other; boxes of
    /// the originals count too). The bound stays certified, only looser.
    size_t maxRefinementsPerDirection = 20000;
    int threadCount = 0;  ///< 0 = hardware concurrency; results identical for every count
    /// Leaves refer to their objects (NodeMeshPlace::Kind::Object: read them with readNodeMesh
    /// or viewNodeMesh, the objects kept alive) instead of holding a copy of their triangles:
    /// a world's originals are not held twice. Everything else is the same.
    bool leavesByReference = false;
    /// When not empty: the nodes' meshes go to a new spill file at this path, each as soon as
    /// nothing in the stage needs it in memory (an object's per-object LOD versions once its
    /// ladder is made or read, an aggregate's proxy and coarser versions once those are), and
    /// the rest before the tree is put together and its bounds computed (as spillNodeMeshes
    /// would do afterwards; HierarchyNodes::meshFile holds it), so that a large world's node
    /// meshes are never all held at once. Everything else is the same, for every thread count.
    std::string meshSpillPath;
    /// Optional: called once the meshes are in the spill file (meshSpillPath), so that the
    /// caller can hand the freed pages back to the system (the allocator may keep them; the
    /// bake calls glibc's malloc_trim).
    std::function<void()> releaseFreedMemory;
    ProgressCallback progress;  ///< optional, stage "proxies"; called from the calling thread only
    /// Optional: keeps every work item of the proxies (an aggregate's proxy, an object's
    /// versions, an aggregate's coarser versions) under a hash of its whole input and reads it
    /// back instead of making it again, so a rebake after a local change redoes only the items
    /// it touched, and separate processes can share the work (buildProxyShare). The nodes are
    /// bit-identical with or without. Called from several threads at once (tile_cache.h).
    /// Required for a hierarchy whose meshes a lean assembly left in the tile cache
    /// (TiledBakeOptions::leanMeshes): they are read back from it where needed.
    const TileCache* cache = nullptr;
};

/// One-sided Hausdorff distances between a proxy and the original objects it stands for:
/// certified upper bounds (never below the true distance, up to double rounding; for
/// originals -> proxy this assumes a closed proxy, as inside-ness is decided by ray parity)
/// and the largest distance found.
struct ProxyError {
    double proxyToOriginals = 0;  ///< upper bound: every proxy point is this close to an original surface
    double originalsToProxy = 0;  ///< upper bound: every original point is inside the proxy or this close to it
    double proxyToOriginalsLower = 0;  ///< largest distance found at an evaluated proxy point
    double originalsToProxyLower = 0;  ///< largest distance found at an evaluated original point
    double tolerance = 0;         ///< allowed gap between found and bound (world units)
    size_t evaluationCount = 0;   ///< regions evaluated, both directions
    /// max(proxyToOriginals, originalsToProxy), world units.
    double bound() const;
};

/// Where a node's mesh is (spillNodeMeshes): in the node's own vectors, or out of memory with
/// its counts kept here. Read it wherever it is with readNodeMesh / viewNodeMesh.
struct NodeMeshPlace {
    enum class Kind : uint8_t {
        InNode,  ///< positions, indices and faceColors of the node
        Object,  ///< a leaf: its object's triangles as given (float positions), as the bake copies them
        File     ///< HierarchyNodes::meshFile at `offset`
    };
    Kind kind = Kind::InNode;
    uint64_t offset = 0;         ///< Kind::File: byte offset in the spill file
    uint32_t vertexCount = 0;    ///< out of the node (Object, File): its counts
    uint32_t triangleCount = 0;
    bool hasFaceColors = false;
};

class NodeMeshFile;  ///< the spill file of spillNodeMeshes (node_mesh_spill.cpp)

struct HierarchyNode {
    uint32_t parent = kNoNode;         ///< index in HierarchyNodes::nodes; kNoNode for roots
    std::vector<uint32_t> children;    ///< node indices, ascending (all smaller than this node's)
    std::vector<uint32_t> sources;     ///< original object indices, ascending
    bool leaf = false;                 ///< an original object (node index = object index)
    /// 0 for leaves and aggregates; j >= 1 for the j-th simplified version of a single object
    /// (per-object LOD below the aggregation levels; sources holds that one object, firstLevel
    /// and lastLevel are -1, j rises towards the root of its chain).
    int objectLod = 0;
    /// 0 for leaves, aggregates and per-object LODs; j >= 1 for the j-th coarser version of
    /// the aggregate below it (its only child is that aggregate or the (j-1)-th version):
    /// an enclosing simplification of the aggregate's proxy with an error between the
    /// aggregate's and its parent's. sources and delta are the aggregate's, firstLevel and
    /// lastLevel are -1 (no level of its own).
    int coarserStep = 0;
    /// 0 for every other node; j >= 1 for the j-th bundle below an aggregate of several
    /// objects (j rises towards it): the drawn versions of the aggregate's children merged into
    /// one mesh, error between theirs and the aggregate's (ProxySettings::bundleCount). sources
    /// are the objects of the children it holds (all or some: a coarser bundle may hold more),
    /// delta is the aggregate's, firstLevel and lastLevel are -1. Its shells are its parts'
    /// (closed proxies, never originals) and may overlap one another. An aggregate whose
    /// children all joined its bundles may give way to the bundles of the group above: its
    /// finer bundles then hang below the bundle of that group it joins.
    int bundleStep = 0;
    int bundleLevel = -1;              ///< bundles: the first level of the aggregate they were made for
    int firstLevel = -1;               ///< levels [firstLevel, lastLevel] of the Hierarchy3D
    int lastLevel = -1;                ///<   this aggregate stands for; -1 for leaves
    uint32_t aggregateIndex = 0;       ///< index in levels[firstLevel].aggregates (aggregates only)
    double delta = 0;                  ///< delta of firstLevel, world units (0 for leaves)
    std::vector<float> positions;      ///< proxy (leaf: the original; empty for a left-out object), 3 * vertexCount, world units
    std::vector<uint32_t> indices;     ///< 3 * triangleCount, outward
    /// Per proxy triangle, linear RGBA (4 * triangleCount): the base colour of the original
    /// surface nearest to the triangle's centroid (leaf: the object's triangleColors).
    /// Empty when none of the sources has colours (every face white).
    std::vector<float> faceColors;
    size_t exactTriangleCount = 0;     ///< triangles of the unsimplified aggregate (leaf: of the object)
    ProxyError error;                  ///< measured error of this node's proxy (zeros for leaves)
    /// Error budget the proxy was made for, world units (0 for leaves): error.bound() <= budget.
    double budget = 0;
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
    /// Where the mesh is: InNode unless spillNodeMeshes moved it out (then positions, indices and
    /// faceColors are empty).
    NodeMeshPlace meshPlace;
};

struct HierarchyNodes {
    /// Leaves first (node i = object i for i < objectCount), then the aggregate nodes by
    /// firstLevel and aggregate index. Children always come before their parent.
    std::vector<HierarchyNode> nodes;
    std::vector<uint32_t> roots;       ///< ascending
    size_t objectCount = 0;
    /// nodeOfAggregate[k][g]: node standing for levels[k].aggregates[g] (an aggregate of one
    /// object that gave way to its per-object LOD chain: the chain's top, or the highest node
    /// of the chain left below a bundle; an aggregate that gave way to the bundles of a group
    /// above: the highest node left of its chain, often one of its own bundles).
    std::vector<std::vector<uint32_t>> nodeOfAggregate;
    /// Work items of the proxies made in this run and read from ProxySettings::cache.
    size_t proxyItemsMade = 0, proxyItemsLoaded = 0;
    /// Originals whose search structures this run built (for the items it made).
    size_t originalsPrepared = 0;
    /// The spill file holding the meshes spillNodeMeshes moved out (null before); shared by
    /// copies of these nodes, closed and removed with the last of them.
    std::shared_ptr<const NodeMeshFile> meshFile;
};

/// One share of buildHierarchyNodes's work, for processes that share ProxySettings::cache
/// (aggrelod-farm). Phase 1 makes the proxies of the aggregates of several objects and every
/// object's versions; phase 2, which reads all of phase 1 from the cache, the proxies of the
/// aggregates of one object that stay and the coarser versions of every aggregate. The items
/// of a phase are dealt to the `parts` shares by their estimated work, heaviest first, each to
/// the share with the least so far (one object's aggregates of phase 2 go together).
struct ProxyShare {
    int phase = 1;       ///< 1 or 2
    uint32_t part = 0;   ///< < parts
    uint32_t parts = 1;  ///< >= 1
};

/// Builds the node tree of `hierarchy`, baked from `objects` (same array, same order).
/// An object the bake left out (in no aggregate of any level, e.g. for a non-finite
/// coordinate) becomes a root leaf without geometry.
/// Returns false with a message in `error` when the two do not match (a source index out of
/// range, an object in two aggregates of one level or in some levels only, a level not
/// coarser than the previous one). Never throws for such input.
bool buildHierarchyNodes(const Hierarchy3D& hierarchy, const std::vector<InputObject>& objects,
                         const ProxySettings& settings, HierarchyNodes& out, std::string& error);

/// Makes one share of the proxies of `hierarchy` into settings.cache (required) and nothing
/// else; buildHierarchyNodes with the same cache afterwards makes only what no share made.
/// `made` and `loaded` (optional) count the share's work items, `prepared` (optional) the
/// originals it built search structures for (a share takes the items of one part of the
/// world, so about its part of them). Returns false with a message
/// in `error` for what buildHierarchyNodes refuses, a share out of range, no cache, or (phase
/// 2) a phase-1 item missing from the cache, named. The cache's entries do not depend on how
/// the work was shared.
bool buildProxyShare(const Hierarchy3D& hierarchy, const std::vector<InputObject>& objects,
                     const ProxySettings& settings, const ProxyShare& share, std::string& error,
                     size_t* made = nullptr, size_t* loaded = nullptr, size_t* prepared = nullptr);

/// Triangles of node n's mesh, wherever it is (NodeMeshPlace).
size_t nodeTriangleCount(const HierarchyNode& n);

/// Moves the meshes of `nodes` out of memory, for writers that read them back a node at a
/// time (a large world's node meshes are most of what a bake holds at its end): a leaf with
/// geometry refers to its object in `objects` (the array the nodes were built from, which must
/// outlive the nodes' use), every other non-empty mesh goes to a new spill file at `path`
/// (removed when the last HierarchyNodes sharing it goes). Nodes already out stay. False with
/// a message naming the file when it cannot be written (the nodes are then unchanged).
bool spillNodeMeshes(HierarchyNodes& nodes, const std::vector<InputObject>& objects, const std::string& path,
                     std::string& error);

/// A node's mesh read back (fields as in HierarchyNode).
struct NodeMesh {
    std::vector<float> positions;
    std::vector<uint32_t> indices;
    std::vector<float> faceColors;
};

/// Node `node`'s mesh, wherever it is, into `out`: the same vectors the node held before
/// spillNodeMeshes. False with a message when the spill file cannot be read back or does not
/// match. Safe to call from several threads at once.
bool readNodeMesh(const HierarchyNodes& nodes, const std::vector<InputObject>& objects, uint32_t node, NodeMesh& out,
                  std::string& error);

/// Node `node`'s mesh as three vectors: the node's own when it is in memory (no copy), else
/// read back into `storage`. Throws std::runtime_error where readNodeMesh fails.
struct NodeMeshView {
    const std::vector<float>& positions;
    const std::vector<uint32_t>& indices;
    const std::vector<float>& faceColors;
};
NodeMeshView viewNodeMesh(const HierarchyNodes& nodes, const std::vector<InputObject>& objects, uint32_t node,
                          NodeMesh& storage);

/// The aggregate node that coarser version `node` simplifies (the end of its chain of single
/// children); for a bundle, the aggregate above its chain of bundles (for the bundles of an
/// aggregate that gave way to a group above, that group's: their own level is bundleLevel;
/// for the bundles of a tree's roots, the root, a bundle); `node` itself otherwise.
/// `node` < nodes.nodes.size().
uint32_t aggregateBelow(const HierarchyNodes& nodes, uint32_t node);

/// Measures the error of a proxy (float positions, 3 * vertexCount; indices 3 * triangleCount,
/// closed) against `originals` (world units) by branch and bound over triangles and, for
/// originals -> proxy, boxes of per-object BVHs: refines until the bounds are within
/// `tolerance` (world units) or when a direction has spent maxRefinementsPerDirection
/// evaluations beyond one per triangle of its measured side. An empty proxy (nothing drawn) gets
/// originalsToProxy = the diagonal of the originals' box. Deterministic, single thread.
ProxyError measureProxyError(const std::vector<float>& proxyPositions,
                             const std::vector<uint32_t>& proxyIndices,
                             const std::vector<const InputObject*>& originals, double tolerance,
                             size_t maxRefinementsPerDirection);

/// Every certified enclosing version of one object, as the bake makes them for its per-object
/// LOD chain (docs/design.md §2.6) but not cut at any group's error: conservative
/// simplifications at error targets sqrt(2) apart from a thousandth of the object's box
/// diagonal (a support surface's: a four-thousandth) up to the diagonal, and enclosing polytopes of its convex hull. Each is closed,
/// contains the object (or `standIn`, the closed solid that stands in for an object that is
/// not one: its SolidReport, or null) and carries its certified error (world units) in
/// `error`; `positions`, `indices` and `budget` are filled, the tree fields are not.
/// Ascending by error. A support surface (`support`, Hierarchy3D::supportObjects) that is not
/// a closed solid is simplified from a thin solid made for it, as the bake does. Empty for an
/// other object that is not a closed solid and has no stand-in, or for one that has a
/// non-finite coordinate or an index out of range. Deterministic, single thread.
std::vector<HierarchyNode> enclosingVersions(const InputObject& object, const SolidReport* standIn,
                                             const ProxySettings& settings, bool support = false);

}  // namespace aggrelod
