// SPDX-License-Identifier: MIT
// aggrelod runtime: the whole contract between the bake and the runtime (as Recast's
// dtNavMeshCreateParams). The module fills a BuildArrays (aggrelod/hierarchy_export.h); its
// BuildParams view of pointers and counts goes to writeRuntimeFile, which turns it into the
// versioned `.aglod` blob that the runtime reads in place (docs/design.md §4). The one node
// record is the file's own. Standard library only: the one runtime header the module may
// include (it links nothing of the runtime).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace aggrelod::runtime {

/// No parent / no index.
constexpr uint32_t kNoIndex = 0xFFFFFFFFu;

/// One node of the hierarchy, exactly as the file stores it (88 bytes, little-endian; the
/// reader's RuntimeFile::node returns it in place). Leaves are the original objects
/// (geometricError 0, level kLeafLevel); inner nodes are aggregates (proxies, level 0, 1, ...)
/// or simplified versions of one object (level kObjectLodLevel, between a leaf and its first
/// aggregate). Ranges index the arrays of BuildParams (and of the file).
struct NodeRecord {
    uint32_t parent = kNoIndex;      ///< index into the nodes; kNoIndex for roots
    uint32_t firstChild = 0;         ///< range [firstChild, firstChild+childCount) in childIndices
    uint32_t childCount = 0;
    uint32_t firstSource = 0;        ///< range in sourceObjects: original objects this node stands for
    uint32_t sourceCount = 0;
    uint32_t firstVertex = 0;        ///< range in positions/normals/colors, counted in vertices
    uint32_t vertexCount = 0;
    uint32_t firstIndex = 0;         ///< range in indices (counted in indices, 3 per triangle);
    uint32_t indexCount = 0;         ///<   indices are relative to firstVertex
    uint32_t level = 0;              ///< 0 = finest aggregate level, rising with delta; kLeafLevel
                                     ///<   for originals, kObjectLodLevel for per-object LODs,
                                     ///<   kCoarserLevel for coarser versions of an aggregate,
                                     ///<   kBundleLevelFlag | k for bundles (isBundleLevel)
    float delta = 0.0f;              ///< threshold of the level, world units (0 for leaves)
    float geometricError = 0.0f;     ///< world units; >= every child's (0 for leaves)
    float boundsMin[3] = {0, 0, 0};  ///< axis-aligned box, world units, contains the children's
    float boundsMax[3] = {0, 0, 0};
    float sphereCenter[3] = {0, 0, 0};  ///< bounding sphere, contains the children's
    float sphereRadius = 0.0f;
};
static_assert(sizeof(NodeRecord) == 88, "NodeRecord is the on-disk layout");

/// Level of the leaves (the original objects).
constexpr uint32_t kLeafLevel = 0xFFFFu;
/// Level of a per-object LOD node: a simplified version of one object (sourceCount 1, delta 0),
/// in the chain between that object's leaf and its first aggregate. Ranked finer than
/// aggregate level 0 and coarser than the leaves (cutAtLevel, levelsOf).
constexpr uint32_t kObjectLodLevel = 0xFFFEu;
/// Level of a coarser version of an aggregate: an enclosing simplification of the proxy of
/// its only child (that aggregate, or the next finer version), error between the aggregate's
/// and its parent's; same objects, same delta. No level of its own: a cut at a level passes
/// through it (cutAtLevel), levelsOf does not list it; selection by screen-space error draws it.
constexpr uint32_t kCoarserLevel = 0xFFFDu;
/// Aggregate levels are < kMaxAggregateLevel; larger values other than the two above and the
/// bundle levels below are refused.
constexpr uint32_t kMaxAggregateLevel = 0xFF00u;
/// Level of a bundle: kBundleLevelFlag | k, k the level of the aggregate it was made for
/// (k < kMaxAggregateLevel). A bundle is the drawn versions of that aggregate's children
/// merged into one mesh, so that a distant group costs one draw call: same objects, error
/// between the children's and the aggregate's. The bundles of an aggregate form a chain below
/// it; an aggregate whose children are all bundled may give way to the bundles of a group
/// above, its finer bundles then hang below that group's finest. The roots of a bake with
/// several (support surfaces beside the hierarchy) are bundled the same way, at k = the number
/// of aggregate levels: the coarsest such bundle is a root and stands for no aggregate. A
/// bundle ranks between levels k - 1 and k; a bundle may stand under another of the same
/// level. No level of its own: a cut at a level passes through it (cutAtLevel) unless it
/// stands for an aggregate that gave way, levelsOf lists no level for it otherwise; selection
/// by screen-space error draws it.
constexpr uint32_t kBundleLevelFlag = 0x10000u;
/// True for a bundle's level (kBundleLevelFlag | k with k < kMaxAggregateLevel).
constexpr bool isBundleLevel(uint32_t level) {
    return (level & ~0xFFFFu) == kBundleLevelFlag && (level & 0xFFFFu) < kMaxAggregateLevel;
}

/// Float rounding in the nesting of bounds, decided here for the bake, the reader and the
/// selector. The reader accepts a child's sphere or box that pokes out of its parent's by up to
/// kNestingSlack × (|parent's coordinates| + 1) (world units). The bake rounds bounds outwards
/// to float and grows every sphere radius by the relative kSphereMargin, so its files stay far
/// inside that slack; the selector grows a parent's sphere by the same margin over its children
/// to close whatever slack a file uses (sse must never grow down a path).
constexpr double kNestingSlack = 1e-5;
constexpr double kSphereMargin = 1e-6;

/// Everything the runtime file holds, as views of arrays the caller owns (pointer and count;
/// a null pointer is allowed with a count of 0). The whole contract between the bake and the
/// runtime; BuildArrays owns such arrays and hands out this view.
struct BuildParams {
    const NodeRecord* nodes = nullptr;  ///< parents may come before or after children
    size_t nodeCount = 0;
    const uint32_t* childIndices = nullptr;  ///< node indices
    size_t childIndexCount = 0;
    const uint32_t* sourceObjects = nullptr;  ///< original object indices in [0, objectCount)
    size_t sourceObjectCount = 0;
    const float* positions = nullptr;  ///< xyz per vertex, world units (3 floats per vertex)
    const float* normals = nullptr;    ///< unit, outward, 3 floats per vertex (normalCount == positionCount)
    const uint8_t* colors = nullptr;   ///< base colour, 4 bytes per vertex (encodeColorSrgb8)
    size_t positionCount = 0;          ///< floats in positions (3 per vertex)
    size_t normalCount = 0;            ///< floats in normals
    size_t colorCount = 0;             ///< bytes in colors (4 per vertex)
    const uint32_t* indices = nullptr; ///< 3 per triangle, relative to the node's firstVertex
    size_t indexCount = 0;
    const std::string* objectNames = nullptr;  ///< name of each original object (UTF-8)
    size_t objectCount = 0;
    uint64_t settingsHash = 0;         ///< hash of the bake settings (for cache invalidation)
    std::string_view toolVersion;      ///< e.g. "0.1.0"
};

/// Arrays behind a BuildParams, owned (what the bake fills; field meanings as in BuildParams).
struct BuildArrays {
    std::vector<NodeRecord> nodes;
    std::vector<uint32_t> childIndices;
    std::vector<uint32_t> sourceObjects;
    std::vector<float> positions;
    /// A mesh vertex on a crease or a colour boundary is split into one vertex per side.
    std::vector<float> normals;
    /// RGB sRGB-encoded (as an SRGB8_ALPHA8 texel), alpha linear; see encodeColorSrgb8.
    std::vector<uint8_t> colors;
    std::vector<uint32_t> indices;
    std::vector<std::string> objectNames;
    uint64_t settingsHash = 0;
    std::string toolVersion;

    /// Views of these arrays (valid while they are neither resized nor destroyed).
    BuildParams params() const {
        BuildParams p;
        p.nodes = nodes.data();
        p.nodeCount = nodes.size();
        p.childIndices = childIndices.data();
        p.childIndexCount = childIndices.size();
        p.sourceObjects = sourceObjects.data();
        p.sourceObjectCount = sourceObjects.size();
        p.positions = positions.data();
        p.positionCount = positions.size();
        p.normals = normals.data();
        p.normalCount = normals.size();
        p.colors = colors.data();
        p.colorCount = colors.size();
        p.indices = indices.data();
        p.indexCount = indices.size();
        p.objectNames = objectNames.data();
        p.objectCount = objectNames.size();
        p.settingsHash = settingsHash;
        p.toolVersion = toolVersion;
        return p;
    }
};

/// Serialises params into a `.aglod` blob (little-endian, 16-byte aligned sections,
/// offsets not pointers). Returns false and fills error when params are inconsistent
/// (a range outside its array, a child whose parent differs, ...). Deterministic:
/// the same params give byte-identical bytes. Implemented in runtime/src/runtime_writer.cpp;
/// the result is checked by the reader's validator (RuntimeFile::openMemory), which requires:
/// - every range inside its array, every triangle index < the node's vertexCount,
///   indexCount a multiple of 3, positions.size() a multiple of 3, normals.size() ==
///   positions.size(), colors.size() == 4 * vertex count, finite floats, normals of unit
///   length (within 1e-3),
///   geometricError/sphereRadius/delta >= 0, boundsMin <= boundsMax;
/// - parent/children consistent (each non-root listed exactly once, by its parent), no cycle,
///   at least one node;
/// - level kLeafLevel exactly for the leaves; kCoarserLevel only on an inner node with one
///   child; kObjectLodLevel only on an inner node standing
///   for one object; bundle levels (isBundleLevel) on inner nodes; any other level <
///   kMaxAggregateLevel;
/// - each leaf (childCount 0) stands for >= 1 object, every object in exactly one leaf, an
///   inner node lists exactly the objects of its leaves (any order, no duplicates);
/// - child error <= parent error (exact), child sphere and box inside the parent's (slack
///   kNestingSlack relative to the parent's coordinates).
bool writeRuntimeFile(const BuildParams& params, std::vector<uint8_t>& bytes, std::string& error);
/// The same for arrays the caller holds as a BuildArrays.
inline bool writeRuntimeFile(const BuildArrays& arrays, std::vector<uint8_t>& bytes, std::string& error) {
    return writeRuntimeFile(arrays.params(), bytes, error);
}
/// The same file written straight to `path` (the bytes writeRuntimeFile gives, never the whole
/// file in memory): `arrays` are consumed (emptied once written, before the file is read back
/// and checked with RuntimeFile::openFile), so a large hierarchy is not held twice. On failure
/// nothing is left at `path`.
bool writeRuntimeFile(BuildArrays&& arrays, const std::string& path, std::string& error);

/// Writes a `.aglod` file a node at a time: the bytes writeRuntimeFile gives for the same
/// arrays, without the vertex and index arrays in memory (they wait in spill files beside
/// `path`, removed when done), for hierarchies too large to hold twice. Call open, then addNode
/// once per node in node order, then finish, which lays the file out, writes it and checks it
/// with RuntimeFile::openFile (refusing what the reader would refuse). On any failure, or when
/// the writer is destroyed before finish succeeds, nothing is left at `path`.
class RuntimeFileStreamWriter {
public:
    RuntimeFileStreamWriter();
    ~RuntimeFileStreamWriter();
    RuntimeFileStreamWriter(const RuntimeFileStreamWriter&) = delete;
    RuntimeFileStreamWriter& operator=(const RuntimeFileStreamWriter&) = delete;

    /// objectNames: one per original object (UTF-8); toolVersion: shorter than 24 bytes.
    bool open(const std::string& path, std::vector<std::string> objectNames, uint64_t settingsHash,
              std::string toolVersion, std::string& error);
    /// The next node. record's ranges (firstChild/childCount, firstSource/sourceCount,
    /// firstVertex/vertexCount, firstIndex/indexCount) are set here from the arrays given; its
    /// other fields are written as they are. children: childCount node indices; sources:
    /// sourceCount object indices; positions and normals: 3 * vertexCount floats (world units,
    /// unit normals); colors: 4 * vertexCount bytes (encodeColorSrgb8); indices: indexCount,
    /// relative to this node's first vertex. Null pointers only with a count of 0.
    bool addNode(NodeRecord record, const uint32_t* children, size_t childCount, const uint32_t* sources,
                 size_t sourceCount, const float* positions, const float* normals, const uint8_t* colors,
                 size_t vertexCount, const uint32_t* indices, size_t indexCount, std::string& error);
    bool finish(std::string& error);

private:
    struct State;
    State* state_;
};

/// Linear RGBA in [0, 1] (glTF baseColorFactor / COLOR_0 meaning; clamped, NaN -> 0) to the
/// file's colour bytes: RGB through the sRGB transfer function, alpha linear, rounded to
/// nearest. decodeColorSrgb8 is its inverse up to that rounding (exact for the 256 codes).
/// Inline: the bake encodes with the same code the runtime decodes with, without linking it.
inline void encodeColorSrgb8(const float linear[4], uint8_t out[4]) {
    auto clampUnit = [](float v) { return v > 0.0f ? std::min(v, 1.0f) : 0.0f; };  // NaN -> 0
    auto toByte = [](float unit) { return static_cast<uint8_t>(std::lround(unit * 255.0f)); };
    auto linearToSrgb = [](float c) { return c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f; };
    for (int k = 0; k < 3; ++k) out[k] = toByte(linearToSrgb(clampUnit(linear[k])));
    out[3] = toByte(clampUnit(linear[3]));
}
inline void decodeColorSrgb8(const uint8_t encoded[4], float linear[4]) {
    auto srgbToLinear = [](float c) { return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f); };
    for (int k = 0; k < 3; ++k) linear[k] = srgbToLinear(encoded[k] / 255.0f);
    linear[3] = encoded[3] / 255.0f;
}

}  // namespace aggrelod::runtime
