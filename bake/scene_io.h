// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod bake: scene files in and out (glTF via tinygltf, stats JSON).
// This is the only place that knows file formats; module/ sees plain meshes.
#pragma once

#include <aggrelod/aggregate3d.h>
#include <aggrelod/collision_shapes.h>
#include <aggrelod/hierarchy_nodes.h>
#include <aggrelod/tile_cache.h>

#include <string>
#include <vector>

namespace aggrelod::io {

/// What one input object is.
enum class ObjectUnit {
    Node,    ///< every node with a mesh is one object (all its triangle primitives together)
    Subtree  ///< every child of a scene root, with all meshes below it, is one object
};

struct SceneReadOptions {
    /// ECMAScript regex, searched in each node's name and in its index path ("@0/3/1": the
    /// node's position in the scene's root list, then child positions). A match leaves the
    /// node out with its subtree. A match on "mesh:" followed by the node's mesh name, or on
    /// the name or path followed by "/mesh" (e.g. '^Terrain/mesh$'), drops only the node's
    /// own mesh and keeps its children.
    std::string excludeRegex;
    ObjectUnit objectUnit = ObjectUnit::Node;
    /// >= 0: every node at this depth (0 = scene roots), with all meshes below it, is one
    /// object; meshes of shallower nodes are objects of their own. Overrides objectUnit.
    int objectDepth = -1;
    /// Nodes targeted by an animation channel (with their subtrees) and skinned meshes are
    /// left out with a note listing them, unless this is set (then their rest pose is read).
    bool includeAnimated = false;
    /// External files (buffer uris) may lie outside the input's folder. Off by default: a
    /// uri such as "../../etc/passwd" is refused, so a file cannot pull in other data.
    bool allowExternalUris = false;
    /// Read every scene of the file (in order; a node that is a root of several scenes is
    /// read once) instead of the default scene only. levels.glb has one scene per level and
    /// proxies.glb keeps its coarser stand-ins in a second scene (docs/engines.md).
    bool allScenes = false;
};

struct SceneReadResult {
    std::vector<InputObject> objects;    ///< world-space triangles, ids = order of appearance
    std::vector<Diagnostic> diagnostics; ///< skipped primitives, unknown extensions, ...
    std::vector<std::string> externalFiles;  ///< canonical paths of the external buffer files read
};

/// Reads a .glb or .gltf file. Returns false with a message in `error` when the file
/// cannot be read at all (missing, truncated, not glTF). Never throws.
bool readGltfScene(const std::string& path, const SceneReadOptions& options,
                   SceneReadResult& out, std::string& error);

/// One mesh node of a levels.glb file (written by writeLevelsGlb).
struct LevelsGlbNode {
    std::string name;                ///< node name, e.g. "level2_group5"
    uint32_t level = 0;              ///< extras.level
    uint32_t group = 0;              ///< extras.group (aggregate index in its level)
    double delta = 0;                ///< extras.delta, world units
    uint32_t sourceCount = 0;        ///< size of extras.sources (1: an original object, not merged)
    std::vector<double> positions;   ///< world space, 3 per vertex
    std::vector<uint32_t> indices;   ///< 3 per triangle
};

/// Reads a levels.glb written by `aggrelod bake`: every node with a mesh, in file order, with
/// its extras. False with a message naming the node when the file cannot be read or a mesh
/// node lacks extras.level (not a levels.glb). Never throws.
bool readLevelsGlb(const std::string& path, std::vector<LevelsGlbNode>& out, std::string& error);

/// One glTF node of a proxies.glb file (written by writeProxiesGlb; layout in docs/engines.md).
struct ProxiesGlbNode {
    std::string name;                ///< e.g. "sphere03_LOD0", "node140_LOD2"
    int gltfNode = -1;               ///< index in the file's nodes
    int node = -1;                   ///< extras.node: the hierarchy (runtime) node; -1 for a group node
    int lod = -1;                    ///< extras.lod: place in its LOD group, 0 = finest
    int childrenOf = -1;             ///< extras.children_of of a group node (LOD0 of a merge), else -1
    bool leaf = false;               ///< extras.leaf: an original object
    bool inDefaultScene = false;     ///< reached from the default scene
    std::vector<int> children;       ///< glTF node indices
    std::vector<int> lodIds;         ///< MSFT_lod ids (glTF node indices), coarser first to coarsest
    std::vector<double> screenCoverage;  ///< extras.MSFT_screencoverage
    bool hasNormals = false, hasColors = false;  ///< every primitive of its mesh has NORMAL / COLOR_0
    std::vector<double> positions;   ///< world space, 3 per vertex (empty without a mesh)
    std::vector<uint32_t> indices;   ///< 3 per triangle
    std::vector<float> triangleColors;  ///< as InputObject::triangleColors
};

/// Reads every node of a proxies.glb (index order), its extras, MSFT_lod and geometry.
/// False with a message when the file cannot be read. Never throws.
bool readProxiesGlb(const std::string& path, std::vector<ProxiesGlbNode>& out, std::string& error);

/// Writes objects as a GLB, one node (with extras.id) per object. For samples and tests.
/// An object with triangleColors gets one material of that colour when all its triangles
/// share it, else COLOR_0 vertex colours (so reading the file back gives the same colours).
bool writeObjectsGlb(const std::vector<InputObject>& objects, const std::string& path,
                     std::string& error);

/// Writes OUTDIR/levels.glb: one node per aggregate per level, grouped under one parent
/// node per level; extras {level, delta, sources: [input object names]}. With `nodes`
/// (the hierarchy nodes of the same bake), each aggregate's extras also carry its node of
/// the runtime hierarchy: node, parent, children (node indices; index < object count = that
/// original object), first_level, last_level, geometric_error (stored, monotone),
/// proxy_error {proxy_to_originals, originals_to_proxy (certified upper bounds),
/// proxy_to_originals_found, originals_to_proxy_found (largest distances found), tolerance, bound},
/// proxy_triangles. World units throughout. Aggregates with face colours carry them as
/// COLOR_0 (linear RGBA) and the level materials are white; without colours each level's
/// material has its own tint.
/// Meshes are made on up to `threadCount` threads (0: all cores); the file is the same for any.
/// The meshes of aggregates a lean assembly left in the tile cache (Aggregate::meshInCache)
/// are read back from `meshCache`, a run of aggregates at a time.
bool writeLevelsGlb(const Hierarchy3D& hierarchy, const std::vector<InputObject>& objects,
                    const std::string& path, std::string& error,
                    const HierarchyNodes* nodes = nullptr, int threadCount = 1, const TileCache* meshCache = nullptr);

/// Writes OUTDIR/proxies.glb: glTF node i = hierarchy node i, nested as the hierarchy (scene
/// roots = its roots). Aggregate nodes carry their simplified proxy as a mesh (one material
/// per level; face colours as COLOR_0 as in levels.glb) and extras {node, level, last_level, delta, geometric_error, proxy_error_bound,
/// exact_triangles, bounding_sphere [x, y, z, r], sources, source_ids}; leaves (the original
/// objects, named "object_<name>") have no mesh and extras {node, leaf, geometric_error 0,
/// bounding_sphere, sources, source_ids}. World units. Meshes are made on up to `threadCount`
/// threads (0: all cores); the file is the same for any.
bool writeProxiesGlb(const HierarchyNodes& nodes, const std::vector<InputObject>& objects,
                     const std::string& path, std::string& error, int threadCount = 1);

/// A named set of hierarchy nodes that covers every object once (a scene of collision.glb).
struct CollisionCut {
    std::string name;              ///< e.g. "level0", "originals", "object_lods"
    std::vector<uint32_t> nodes;   ///< hierarchy node indices
};

/// Writes OUTDIR/collision.glb (docs/engines.md): per hierarchy node with geometry a static
/// collider node "<stem>_collider" with its mesh as a triangle-mesh shape, and, when
/// shapes[i] has a convex decomposition, a node "<stem>_convex" whose children are one convex
/// collider each (stem: the object's name for a leaf, "node<i>" otherwise). Colliders carry
/// KHR_physics_rigid_bodies {collider: {geometry: {node: itself, convexHull}}} and
/// OMI_physics_body {collider: {shape}} over the document's OMI_physics_shape shapes (trimesh /
/// convex, the same mesh). Scenes: per cut its trimesh colliders and "<cut>_convex" (convex
/// decompositions where present), then "all_nodes"; the first is the default scene. Collision
/// meshes have POSITION and indices only. World units.
bool writeCollisionGlb(const HierarchyNodes& nodes, const std::vector<InputObject>& objects,
                       const std::vector<NodeCollisionShapes>& shapes, const std::vector<CollisionCut>& cuts,
                       const std::string& path, std::string& error);

/// The base colour (linear RGBA, 4 values) of level `level` of `levelCount` in levels.glb and
/// proxies.glb: warm for fine levels, cool for coarse ones.
std::vector<double> levelBaseColour(size_t level, size_t levelCount);

/// The content of one 3D Tiles tile (see tiles_export.h): one mesh in glTF (y-up) world
/// coordinates, world units.
struct TileMesh {
    std::string name;                 ///< glTF node, mesh and material name
    std::vector<float> positions;     ///< 3 * vertexCount
    std::vector<uint32_t> indices;    ///< 3 * triangleCount, outward
    double baseColor[4] = {0.7, 0.7, 0.7, 1.0};  ///< linear RGBA of the one material
    uint32_t node = 0;                ///< hierarchy node index (extras.node)
    double geometricError = 0;        ///< extras.geometric_error, world units
    std::vector<uint64_t> sourceIds;  ///< extras.source_ids: ids of the original objects
};

/// Writes one tile's GLB: one node with one triangle mesh (or none when `tile` has no
/// triangles) and one material. Deterministic bytes. Returns false with a message naming
/// `path` on a bad mesh (index out of range) or a write error.
bool writeTileGlb(const TileMesh& tile, const std::string& path, std::string& error);

/// Writes the stats JSON (see README "Stats file"). Timings are written last, in their
/// own object, so determinism checks can drop them. With `nodes`, each level also gets its
/// proxies' figures (nodes drawn at that level: budget and certified error, max and median,
/// triangles) and "object_lods" the same for the per-object LOD nodes.
bool writeStatsJson(const Hierarchy3D& hierarchy, const std::vector<InputObject>& objects,
                    const std::vector<Diagnostic>& readDiagnostics, const std::string& path,
                    std::string& error, const HierarchyNodes* nodes = nullptr);

}  // namespace aggrelod::io
