// SPDX-License-Identifier: AGPL-3.0-or-later
// The hierarchy nodes as the runtime's flat contract (aggrelod/runtime_build.h, as Recast's
// dtNavMeshCreateParams): one NodeRecord per node and the arrays they index, with render
// normals and per-vertex colours (docs/design.md §4). The runtime's writer turns the result
// into `.aglod` bytes; this side links nothing of the runtime.
#pragma once

#include <aggrelod/hierarchy_nodes.h>
#include <aggrelod/runtime_build.h>

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace aggrelod {

/// Faces meeting at a dihedral angle (between their normals) of more than this are a crease:
/// their shared vertices are split, each side gets its own normal. 60 degrees keeps box edges
/// and steep roof ridges crisp and smooths the coarse facets of rounded proxies (a distant
/// clump of trees should not look like a cut gem).
constexpr double kCreaseAngleDegrees = 60.0;

/// A mesh ready to draw: one normal and one colour per vertex.
struct RenderMesh {
    std::vector<float> positions;   ///< 3 per vertex, world units; copies of the input's, bit-identical
    std::vector<float> normals;     ///< 3 per vertex, unit, outward
    std::vector<uint8_t> colors;    ///< 4 per vertex, runtime::encodeColorSrgb8 of the face colour
    std::vector<uint32_t> indices;  ///< 3 per triangle, the input's triangles in the same order
};

/// Builds the render vertices of a triangle mesh (positions 3 * vertexCount floats, world
/// units; indices 3 * triangleCount). `faceColors`: linear RGBA per triangle (4 *
/// triangleCount floats) or empty for white. Each input vertex becomes one output vertex per
/// group of its corners that are joined across edges shared by exactly two triangles of the
/// same encoded colour whose normals differ by at most kCreaseAngleDegrees. A group's
/// normal is the angle-weighted sum of its faces' unit normals (Thuermer & Wuethrich), so it
/// does not depend on how a flat region is triangulated; degenerate triangles add nothing
/// (a vertex without any usable face gets +z). Output vertices are numbered in order of
/// first use by the triangles: deterministic. Returns false (out empty) when an index is out
/// of range or indices.size() is not a multiple of 3.
bool buildRenderMesh(const std::vector<float>& positions, const std::vector<uint32_t>& indices,
                     const std::vector<float>& faceColors, RenderMesh& out);

/// Receives node i's record (its ranges left 0: the receiver places the arrays) and render mesh.
/// Returns false with `error` filled to stop the export.
using NodeExportSink =
    std::function<bool(size_t node, runtime::NodeRecord record, const RenderMesh& mesh, std::string& error)>;

/// The runtime contract of `nodes` a node at a time, in node order (what exportHierarchy
/// stores, for writers that do not hold it all: runtime::RuntimeFileStreamWriter). Records as
/// exportHierarchy describes; meshes out of memory (spillNodeMeshes) are read back from `objects`
/// and the spill file. The render meshes are built a batch of 1,024 nodes at a time on
/// up to `threadCount` threads (0: all cores), `emit` is called from the calling thread. False
/// with a message when a count does not fit 32 bits, an index is out of range or emit fails.
bool exportHierarchyNodes(const HierarchyNodes& nodes, const std::vector<InputObject>& objects, int threadCount,
                          const NodeExportSink& emit, std::string& error);

/// Fills `out` from `nodes` (node i of the file = nodes.nodes[i]; leaves carry the original
/// object's triangles, aggregates and per-object LODs their simplified proxy, as float world
/// coordinates, with normals and the node's faceColors through buildRenderMesh). Levels:
/// leaves kLeafLevel, per-object LOD nodes (objectLod >= 1) kObjectLodLevel, coarser versions
/// kCoarserLevel, bundles kBundleLevelFlag | the firstLevel of the aggregate above them,
/// aggregates their firstLevel. `objects`: the baked input (names only).
/// Returns false with a message when a count does not fit 32 bits or an index is out of range.
/// The nodes' meshes are built on up to `threadCount` threads (0: all cores). Deterministic:
/// the same output for any thread count.
bool exportHierarchy(const HierarchyNodes& nodes, const std::vector<InputObject>& objects,
                     uint64_t settingsHash, const std::string& toolVersion,
                     runtime::BuildArrays& out, std::string& error, int threadCount = 1);

}  // namespace aggrelod
