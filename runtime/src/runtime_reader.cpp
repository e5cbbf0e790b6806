// SPDX-License-Identifier: MIT
// Reader of the `.aglod` runtime file (docs/design.md §4): checks the header, the checksum,
// the section table, every index range and the tree shape before anything is used, then
// views the arrays in place. All arithmetic on file values is done in 64 bits so that no
// value can overflow into a "valid" range.
#include <aggrelod/runtime_file.h>

#include "aglod_layout.h"
#include "mapped_file.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

namespace aggrelod::runtime {

const char* toString(FileStatus status) {
    switch (status) {
        case FileStatus::Ok: return "ok";
        case FileStatus::IoError: return "cannot read file";
        case FileStatus::WrongMagic: return "wrong magic (not an .aglod file)";
        case FileStatus::WrongVersion: return "wrong version";
        case FileStatus::Truncated: return "truncated";
        case FileStatus::ChecksumMismatch: return "checksum mismatch";
        case FileStatus::BadSection: return "bad section table";
        case FileStatus::IndexOutOfRange: return "index out of range";
        case FileStatus::BadTree: return "bad tree";
        case FileStatus::BadValue: return "bad value";
        case FileStatus::Misaligned: return "buffer not 16-byte aligned";
        case FileStatus::UnsupportedHost: return "big-endian host not supported";
    }
    return "unknown status";
}

RuntimeFile::RuntimeFile() = default;
RuntimeFile::~RuntimeFile() = default;
RuntimeFile::RuntimeFile(RuntimeFile&&) noexcept = default;
RuntimeFile& RuntimeFile::operator=(RuntimeFile&&) noexcept = default;

Span<uint32_t> RuntimeFile::children(uint32_t node) const {
    const NodeRecord& n = nodes_.data[node];
    return {childIndices_.data + n.firstChild, n.childCount};
}
Span<uint32_t> RuntimeFile::sources(uint32_t node) const {
    const NodeRecord& n = nodes_.data[node];
    return {sourceObjects_.data + n.firstSource, n.sourceCount};
}
Span<float> RuntimeFile::vertices(uint32_t node) const {
    const NodeRecord& n = nodes_.data[node];
    return {positions_.data + 3ull * n.firstVertex, 3ull * n.vertexCount};
}
Span<float> RuntimeFile::normals(uint32_t node) const {
    const NodeRecord& n = nodes_.data[node];
    return {normals_.data + 3ull * n.firstVertex, 3ull * n.vertexCount};
}
Span<uint8_t> RuntimeFile::colors(uint32_t node) const {
    const NodeRecord& n = nodes_.data[node];
    return {colors_.data + 4ull * n.firstVertex, 4ull * n.vertexCount};
}
Span<uint32_t> RuntimeFile::triangles(uint32_t node) const {
    const NodeRecord& n = nodes_.data[node];
    return {indices_.data + n.firstIndex, n.indexCount};
}
std::string_view RuntimeFile::objectName(uint32_t object) const {
    return {nameBlob_.data + nameRanges_.data[2 * object], nameRanges_.data[2 * object + 1]};
}

struct FileValidator {
    const uint8_t* base;
    size_t size;
    RuntimeFile& out;
    std::string& message;
    /// The file's mapping (openFile), whose pages the linear passes release behind them.
    const MappedFile* mapping = nullptr;

    /// Releases what a linear pass over [begin, end) has read, every kReleaseStep bytes.
    class ReleaseBehind {
    public:
        static constexpr size_t kReleaseStep = size_t(64) << 20;
        ReleaseBehind(const MappedFile* mapping, const void* begin) : mapping_(mapping), from_(static_cast<const uint8_t*>(begin)) {}
        void reached(const void* at) {
            const auto* p = static_cast<const uint8_t*>(at);
            if (mapping_ == nullptr || p < from_ || size_t(p - from_) < kReleaseStep) return;
            mapping_->release(from_, size_t(p - from_));
            from_ = p;
        }

    private:
        const MappedFile* mapping_;
        const uint8_t* from_;
    };

    FileStatus fail(FileStatus status, std::string text) {
        message = std::move(text);
        return status;
    }

    FileStatus run() {
        using namespace layout;
        if (!hostIsLittleEndian())
            return fail(FileStatus::UnsupportedHost, "the format is little-endian");
        if (reinterpret_cast<uintptr_t>(base) % kSectionAlign != 0)
            return fail(FileStatus::Misaligned, "buffer address is not a multiple of 16");
        if (size < kHeaderSize)
            return fail(FileStatus::Truncated, std::to_string(size) + " bytes, smaller than the " +
                                                   std::to_string(kHeaderSize) + "-byte header");
        if (std::memcmp(base, kMagic, sizeof(kMagic)) != 0)
            return fail(FileStatus::WrongMagic, "the first 8 bytes are not \"AGGRELOD\"");
        const uint16_t major = loadU16(base + 8), minor = loadU16(base + 10);
        if (major != kFormatMajor)
            return fail(FileStatus::WrongVersion, "format version " + std::to_string(major) + "." +
                                                      std::to_string(minor) + ", this reader reads " +
                                                      std::to_string(kFormatMajor) + ".x");
        const uint64_t total = loadU64(base + 16);
        if (total > size)
            return fail(FileStatus::Truncated, "header says " + std::to_string(total) +
                                                   " bytes, only " + std::to_string(size) + " present");
        if (total < size)
            return fail(FileStatus::BadSection, std::to_string(size - total) + " bytes after the declared end (" +
                                                    std::to_string(total) + " bytes)");
        if (total < kHeaderSize || total % kTotalSizeMultiple != 0)
            return fail(FileStatus::BadSection, "total size " + std::to_string(total) +
                                                    " is not a multiple of 32 of at least 64");
        const uint64_t stored = loadU64(base + kChecksumOffset);
        uint64_t actual = 0;
        {
            FileChecksum sum;
            ReleaseBehind read(mapping, base);
            for (size_t at = 0; at < total; at += ReleaseBehind::kReleaseStep) {
                const size_t bytes = std::min<size_t>(ReleaseBehind::kReleaseStep, size_t(total) - at);
                sum.add(base + at, at, bytes, kChecksumOffset);
                read.reached(base + at + bytes);
            }
            actual = sum.value(static_cast<size_t>(total));
        }
        if (stored != actual)
            return fail(FileStatus::ChecksumMismatch, "stored checksum does not match the content");
        // Past the checksum only a writer bug (or a deliberate forgery) can fail; keep checking.
        const uint32_t sectionCount = loadU32(base + 12);
        if (sectionCount < kSectionCount || sectionCount > 4096)
            return fail(FileStatus::BadSection, "section count " + std::to_string(sectionCount));
        const uint64_t tableEnd = kHeaderSize + uint64_t(kSectionEntrySize) * sectionCount;
        if (tableEnd > total) return fail(FileStatus::Truncated, "section table past end of file");
        const char* tool = reinterpret_cast<const char*>(base + 40);
        size_t toolLen = 0;
        while (toolLen < kToolVersionSize && tool[toolLen] != '\0') ++toolLen;
        if (toolLen == kToolVersionSize)
            return fail(FileStatus::BadValue, "tool version is not NUL-terminated");

        const void* data[kSectionCount + 1] = {};
        uint64_t counts[kSectionCount + 1] = {};
        uint64_t previousEnd = tableEnd;
        for (uint32_t s = 1; s <= sectionCount; ++s) {
            const uint8_t* e = base + kHeaderSize + kSectionEntrySize * (s - 1);
            const uint32_t kind = loadU32(e), stride = loadU32(e + 4);
            const uint64_t offset = loadU64(e + 8), count = loadU64(e + 16), bytes = loadU64(e + 24);
            const std::string where = "section " + std::to_string(s);
            if (s <= kSectionCount && kind != s)
                return fail(FileStatus::BadSection, where + " has kind " + std::to_string(kind) +
                                                        ", expected " + std::to_string(s));
            if (s <= kSectionCount && stride != kSectionStride[s])
                return fail(FileStatus::BadSection, where + " (" + kSectionName[s] + ") stride " +
                                                        std::to_string(stride) + ", expected " +
                                                        std::to_string(kSectionStride[s]));
            if (stride == 0 || count > total / stride || count * stride != bytes)
                return fail(FileStatus::BadSection, where + ": count " + std::to_string(count) +
                                                        " x stride " + std::to_string(stride) +
                                                        " != byte size " + std::to_string(bytes));
            if (offset % kSectionAlign != 0 || offset < previousEnd || offset > total ||
                bytes > total - offset)
                return fail(FileStatus::BadSection, where + " at offset " + std::to_string(offset) +
                                                        " (" + std::to_string(bytes) +
                                                        " bytes) is misaligned, overlaps or lies "
                                                        "outside the file");
            previousEnd = offset + bytes;
            if (s <= kSectionCount) {
                data[s] = base + offset;
                counts[s] = count;
            }
        }
        if (counts[kNodes] >= kNoIndex) return fail(FileStatus::BadSection, "too many nodes");
        // Normals and colours are per vertex: the same count as the positions.
        for (uint32_t s : {kNormals, kColors})
            if (counts[s] != counts[kPositions])
                return fail(FileStatus::BadSection, std::string(kSectionName[s]) + ": " + std::to_string(counts[s]) +
                                                        " entries for " + std::to_string(counts[kPositions]) +
                                                        " vertices");

        out.nodes_ = {static_cast<const NodeRecord*>(data[kNodes]), counts[kNodes]};
        out.roots_ = {static_cast<const uint32_t*>(data[kRoots]), counts[kRoots]};
        out.childIndices_ = {static_cast<const uint32_t*>(data[kChildIndices]), counts[kChildIndices]};
        out.sourceObjects_ = {static_cast<const uint32_t*>(data[kSourceObjects]), counts[kSourceObjects]};
        out.positions_ = {static_cast<const float*>(data[kPositions]), 3 * counts[kPositions]};
        out.normals_ = {static_cast<const float*>(data[kNormals]), 3 * counts[kNormals]};
        out.colors_ = {static_cast<const uint8_t*>(data[kColors]), 4 * counts[kColors]};
        out.indices_ = {static_cast<const uint32_t*>(data[kIndices]), counts[kIndices]};
        out.nameRanges_ = {static_cast<const uint32_t*>(data[kNameRanges]), 2 * counts[kNameRanges]};
        out.nameBlob_ = {static_cast<const char*>(data[kNameBlob]), counts[kNameBlob]};
        out.versionMajor_ = major;
        out.versionMinor_ = minor;
        out.settingsHash_ = loadU64(base + 32);
        out.toolVersion_.assign(tool, toolLen);
        out.base_ = base;
        out.byteSize_ = static_cast<size_t>(total);

        if (FileStatus s = checkRanges(); s != FileStatus::Ok) return s;
        return checkTree();
    }

    static bool inRange(uint64_t first, uint64_t count, uint64_t size) {
        return first <= size && count <= size - first;
    }

    /// The non-empty ranges [first, first + count) of the nodes in one array must not overlap:
    /// shared ranges would let a small file cost time and memory quadratic in its size.
    FileStatus checkDisjoint(const char* what, uint32_t NodeRecord::*first, uint32_t NodeRecord::*count) {
        const Span<NodeRecord> nodes = out.nodes_;
        std::vector<std::pair<uint32_t, uint32_t>> ranges;  // (first, node)
        for (uint64_t i = 0; i < nodes.size; ++i)
            if (nodes[i].*count != 0) ranges.emplace_back(nodes[i].*first, uint32_t(i));
        std::sort(ranges.begin(), ranges.end());
        for (size_t k = 1; k < ranges.size(); ++k) {
            const NodeRecord& previous = nodes[ranges[k - 1].second];
            if (uint64_t(previous.*first) + (previous.*count) > ranges[k].first)
                return fail(FileStatus::BadValue, "nodes " + std::to_string(ranges[k - 1].second) + " and " +
                                                      std::to_string(ranges[k].second) + " share " + what);
        }
        return FileStatus::Ok;
    }

    /// Largest magnitude of a stored coordinate, box, sphere, error or delta: inside what ray
    /// tracing (Embree) accepts, far above what a bake writes.
    static constexpr float kMaxMagnitude = 1e18f;

    FileStatus checkRanges() {
        const Span<NodeRecord> nodes = out.nodes_;
        const uint64_t n = nodes.size;
        const uint64_t vertexCount = out.positions_.size / 3;
        for (uint64_t i = 0; i < n; ++i) {
            const NodeRecord& r = nodes[i];
            auto where = [i] { return "node " + std::to_string(i); };  // built only on failure
            if (r.parent != kNoIndex && r.parent >= n)
                return fail(FileStatus::IndexOutOfRange, where() + ": parent " + std::to_string(r.parent) +
                                                             " >= node count " + std::to_string(n));
            if (r.parent == i) return fail(FileStatus::BadTree, where() + " is its own parent");
            if (!inRange(r.firstChild, r.childCount, out.childIndices_.size))
                return fail(FileStatus::IndexOutOfRange, where() + ": children outside the child array");
            if (!inRange(r.firstSource, r.sourceCount, out.sourceObjects_.size))
                return fail(FileStatus::IndexOutOfRange, where() + ": sources outside the source array");
            if (!inRange(r.firstVertex, r.vertexCount, vertexCount))
                return fail(FileStatus::IndexOutOfRange, where() + ": vertices outside the position array");
            if (!inRange(r.firstIndex, r.indexCount, out.indices_.size))
                return fail(FileStatus::IndexOutOfRange, where() + ": triangles outside the index array");
            if (r.indexCount % 3 != 0)
                return fail(FileStatus::BadValue, where() + ": index count " + std::to_string(r.indexCount) +
                                                      " is not a multiple of 3");
            const float values[] = {r.delta, r.geometricError, r.boundsMin[0], r.boundsMin[1],
                                    r.boundsMin[2], r.boundsMax[0], r.boundsMax[1], r.boundsMax[2],
                                    r.sphereCenter[0], r.sphereCenter[1], r.sphereCenter[2],
                                    r.sphereRadius};
            for (float v : values) {
                if (!std::isfinite(v)) return fail(FileStatus::BadValue, where() + ": NaN or infinite value");
                if (std::fabs(v) > kMaxMagnitude)
                    return fail(FileStatus::BadValue, where() + ": value " + std::to_string(v) + " beyond 1e18");
            }
            if (r.geometricError < 0 || r.sphereRadius < 0 || r.delta < 0)
                return fail(FileStatus::BadValue, where() + ": negative error, radius or delta");
            for (int k = 0; k < 3; ++k)
                if (r.boundsMin[k] > r.boundsMax[k])
                    return fail(FileStatus::BadValue, where() + ": box min > max");
            const bool leaf = r.childCount == 0;
            if (leaf != (r.level == kLeafLevel))
                return fail(FileStatus::BadValue, where() + (leaf ? ": a leaf with level " + std::to_string(r.level)
                                                                  : ": an inner node with the leaf level"));
            if (r.level == kObjectLodLevel && r.sourceCount != 1)
                return fail(FileStatus::BadValue, where() + ": per-object LOD node standing for " +
                                                      std::to_string(r.sourceCount) + " objects");
            if (r.level == kCoarserLevel && r.childCount != 1)
                return fail(FileStatus::BadValue, where() + ": coarser version with " + std::to_string(r.childCount) +
                                                      " children");
            if (!leaf && r.level != kObjectLodLevel && r.level != kCoarserLevel && !isBundleLevel(r.level) &&
                r.level >= kMaxAggregateLevel)
                return fail(FileStatus::BadValue, where() + ": level " + std::to_string(r.level));
        }
        if (FileStatus s = checkDisjoint("vertices", &NodeRecord::firstVertex, &NodeRecord::vertexCount);
            s != FileStatus::Ok)
            return s;
        if (FileStatus s = checkDisjoint("triangles", &NodeRecord::firstIndex, &NodeRecord::indexCount);
            s != FileStatus::Ok)
            return s;
        if (FileStatus s = checkDisjoint("source objects", &NodeRecord::firstSource, &NodeRecord::sourceCount);
            s != FileStatus::Ok)
            return s;
        // Disjoint ranges: this pass reads each index at most once.
        ReleaseBehind indicesRead(mapping, out.indices_.data);
        for (uint64_t i = 0; i < n; ++i) {
            const NodeRecord& r = nodes[i];
            indicesRead.reached(out.indices_.data + r.firstIndex);
            for (uint32_t k = 0; k < r.indexCount; ++k)
                if (out.indices_[r.firstIndex + k] >= r.vertexCount)
                    return fail(FileStatus::IndexOutOfRange,
                                "node " + std::to_string(i) + ": triangle index " +
                                    std::to_string(out.indices_[r.firstIndex + k]) + " >= its vertex count " +
                                    std::to_string(r.vertexCount));
        }
        ReleaseBehind positionsRead(mapping, out.positions_.data);
        for (size_t i = 0; i < out.positions_.size; ++i) {
            if (i % 4096 == 0) positionsRead.reached(out.positions_.data + i);
            if (!(std::fabs(out.positions_[i]) <= kMaxMagnitude))
                return fail(FileStatus::BadValue, "vertex " + std::to_string(i / 3) +
                                                      ": NaN, infinite or beyond 1e18 coordinate");
        }
        ReleaseBehind normalsRead(mapping, out.normals_.data);
        for (size_t v = 0; v < out.normals_.size / 3; ++v) {
            const float* nv = out.normals_.data + 3 * v;
            if (v % 4096 == 0) normalsRead.reached(nv);
            const float length2 = nv[0] * nv[0] + nv[1] * nv[1] + nv[2] * nv[2];
            // NaN fails the comparison too.
            if (!(std::fabs(length2 - 1.0f) <= 2.0f * layout::kNormalLengthTolerance))
                return fail(FileStatus::BadValue, "vertex " + std::to_string(v) + ": normal (" + std::to_string(nv[0]) +
                                                      ", " + std::to_string(nv[1]) + ", " + std::to_string(nv[2]) +
                                                      ") is not of unit length");
        }
        for (size_t i = 0; i < out.childIndices_.size; ++i)
            if (out.childIndices_[i] >= n)
                return fail(FileStatus::IndexOutOfRange, "child entry " + std::to_string(i) + ": node " +
                                                             std::to_string(out.childIndices_[i]) + " >= node count");
        const uint64_t objects = out.nameRanges_.size / 2;
        for (size_t i = 0; i < out.sourceObjects_.size; ++i)
            if (out.sourceObjects_[i] >= objects)
                return fail(FileStatus::IndexOutOfRange, "source entry " + std::to_string(i) + ": object " +
                                                             std::to_string(out.sourceObjects_[i]) +
                                                             " >= object count " + std::to_string(objects));
        for (uint64_t o = 0; o < objects; ++o)
            if (!inRange(out.nameRanges_[2 * o], out.nameRanges_[2 * o + 1], out.nameBlob_.size))
                return fail(FileStatus::IndexOutOfRange, "object " + std::to_string(o) + ": name outside the name blob");
        for (size_t i = 0; i < out.roots_.size; ++i) {
            const uint32_t root = out.roots_[i];
            if (root >= n) return fail(FileStatus::IndexOutOfRange, "root " + std::to_string(root) + " >= node count");
            if (i > 0 && root <= out.roots_[i - 1])
                return fail(FileStatus::BadTree, "roots are not strictly increasing");
            if (nodes[root].parent != kNoIndex)
                return fail(FileStatus::BadTree, "root " + std::to_string(root) + " has a parent");
        }
        return FileStatus::Ok;
    }

    static bool sphereInside(const NodeRecord& inner, const NodeRecord& outer) {
        double d2 = 0, scale = outer.sphereRadius;
        for (int k = 0; k < 3; ++k) {
            const double d = double(inner.sphereCenter[k]) - outer.sphereCenter[k];
            d2 += d * d;
            scale = std::max(scale, std::fabs(double(outer.sphereCenter[k])));
        }
        // Float rounding of the bake (runtime_build.h).
        return std::sqrt(d2) + inner.sphereRadius <= outer.sphereRadius + kNestingSlack * (scale + 1.0);
    }
    static bool boxInside(const NodeRecord& inner, const NodeRecord& outer) {
        for (int k = 0; k < 3; ++k) {
            const double slack = kNestingSlack * (std::fabs(double(outer.boundsMin[k])) +
                                         std::fabs(double(outer.boundsMax[k])) + 1.0);
            if (inner.boundsMin[k] < outer.boundsMin[k] - slack ||
                inner.boundsMax[k] > outer.boundsMax[k] + slack)
                return false;
        }
        return true;
    }

    /// Order of levels from fine to coarse: leaves, per-object LODs, aggregate levels 0, 1, ...,
    /// a bundle of level k between k - 1 and k. A child's level must be below its parent's
    /// (per-object LODs and bundles of one level may also chain; a coarser version ranks as the
    /// aggregate it simplifies).
    static int64_t levelRank(uint32_t level) {
        if (level == kLeafLevel) return -4;
        if (level == kObjectLodLevel) return -2;
        if (isBundleLevel(level)) return 2 * int64_t(level & 0xFFFFu) - 1;
        return 2 * int64_t(level);
    }

    FileStatus checkTree() {
        const Span<NodeRecord> nodes = out.nodes_;
        const uint32_t n = static_cast<uint32_t>(nodes.size);
        const uint32_t objects = out.objectCount();
        if (n == 0) return fail(FileStatus::BadTree, "no nodes");
        // Parent/child consistency: each non-root is listed exactly once, by its parent.
        std::vector<uint32_t> references(n, 0);
        // A coarser version ranks as the aggregate it simplifies: the end of its chain of
        // single children (memoised, so the walk is linear in the node count).
        constexpr int64_t kUnknown = std::numeric_limits<int64_t>::min();
        std::vector<int64_t> rank(n, kUnknown);
        std::vector<uint32_t> path;
        for (uint32_t i = 0; i < n; ++i) {
            path.clear();
            uint32_t at = i;
            int64_t found = kUnknown;
            while (found == kUnknown) {
                if (rank[at] != kUnknown) found = rank[at];
                else if (nodes[at].level != kCoarserLevel) found = levelRank(nodes[at].level);
                else if (path.size() > n || out.children(at).size != 1)
                    return fail(FileStatus::BadTree, "node " + std::to_string(i) + ": a coarser version that is not "
                                                     "above exactly one chain of single children");
                else {
                    path.push_back(at);
                    at = out.children(at)[0];
                }
            }
            for (uint32_t p : path) rank[p] = found;
            rank[i] = found;
        }
        uint64_t parentless = 0;
        for (uint32_t i = 0; i < n; ++i) {
            const NodeRecord& r = nodes[i];
            if (r.parent == kNoIndex) ++parentless;
            for (uint32_t c : out.children(i)) {
                if (r.level == kCoarserLevel && (nodes[c].level == kLeafLevel || nodes[c].level == kObjectLodLevel))
                    return fail(FileStatus::BadTree, "node " + std::to_string(i) + ": a coarser version above a " +
                                                         (nodes[c].level == kLeafLevel ? "leaf" : "per-object LOD"));
                if (nodes[c].parent != i)
                    return fail(FileStatus::BadTree, "node " + std::to_string(i) + ": child " + std::to_string(c) +
                                                         " has parent " + std::to_string(nodes[c].parent));
                if (++references[c] > 1)
                    return fail(FileStatus::BadTree, "node " + std::to_string(c) + " is listed twice as a child");
                // Per-object LODs form chains: one may stand under another.
                if (rank[c] >= rank[i] && r.level != kCoarserLevel &&
                    !((r.level == kObjectLodLevel || isBundleLevel(r.level)) && nodes[c].level == r.level))
                    return fail(FileStatus::BadTree, "node " + std::to_string(c) + ": level " +
                                                         std::to_string(nodes[c].level) + " is not below its parent's (" +
                                                         std::to_string(r.level) + ")");
                if (nodes[c].geometricError > r.geometricError)
                    return fail(FileStatus::BadTree, "node " + std::to_string(c) + ": error " +
                                                         std::to_string(nodes[c].geometricError) +
                                                         " exceeds its parent's " + std::to_string(r.geometricError));
                if (!sphereInside(nodes[c], r) || !boxInside(nodes[c], r))
                    return fail(FileStatus::BadTree, "node " + std::to_string(c) +
                                                         ": bounds not inside its parent's (" +
                                                         std::to_string(i) + ")");
            }
        }
        for (uint32_t i = 0; i < n; ++i)
            if (nodes[i].parent != kNoIndex && references[i] != 1)
                return fail(FileStatus::BadTree, "node " + std::to_string(i) + " is not listed by its parent " +
                                                     std::to_string(nodes[i].parent));
        if (parentless != out.roots_.size)
            return fail(FileStatus::BadTree, std::to_string(parentless) + " parentless nodes but " +
                                                 std::to_string(out.roots_.size) + " roots listed");

        // Walk from the roots (explicit stack): every node reached once means no cycle.
        // Preorder intervals [enter, leave) tell ancestry for the coverage check.
        std::vector<uint32_t> enter(n, kNoIndex), leave(n, 0), depth(n, 0), stack;
        stack.reserve(n);
        uint32_t clock = 0, maxDepth = 0;
        for (uint32_t root : out.roots_) {
            stack.push_back(root);
            depth[root] = 1;
            while (!stack.empty()) {
                const uint32_t x = stack.back();
                if (enter[x] == kNoIndex) {
                    enter[x] = clock++;
                    maxDepth = std::max(maxDepth, depth[x]);
                    for (uint32_t c : out.children(x)) {
                        if (enter[c] != kNoIndex) return fail(FileStatus::BadTree, "cycle through node " + std::to_string(c));
                        depth[c] = depth[x] + 1;
                        stack.push_back(c);
                    }
                } else {
                    leave[x] = clock;
                    stack.pop_back();
                }
            }
        }
        if (clock != n)
            return fail(FileStatus::BadTree, std::to_string(n - clock) + " nodes unreachable from the roots (a cycle)");
        out.depth_ = maxDepth;

        // Coverage: leaves partition the objects; an inner node lists exactly the objects of
        // its leaves, so any cut covers every object exactly once.
        std::vector<uint32_t> ownerLeaf(objects, kNoIndex), stamp(objects, kNoIndex);
        for (uint32_t i = 0; i < n; ++i) {
            if (nodes[i].childCount != 0) continue;
            if (nodes[i].sourceCount == 0)
                return fail(FileStatus::BadTree, "leaf node " + std::to_string(i) + " stands for no object");
            for (uint32_t o : out.sources(i)) {
                if (ownerLeaf[o] != kNoIndex)
                    return fail(FileStatus::BadTree, "object " + std::to_string(o) + " is in leaves " +
                                                         std::to_string(ownerLeaf[o]) + " and " + std::to_string(i));
                ownerLeaf[o] = i;
            }
        }
        for (uint32_t o = 0; o < objects; ++o)
            if (ownerLeaf[o] == kNoIndex)
                return fail(FileStatus::BadTree, "object " + std::to_string(o) + " is in no leaf");
        for (uint32_t i = 0; i < n; ++i) {
            const NodeRecord& r = nodes[i];
            if (r.childCount == 0) continue;
            uint64_t sum = 0;
            for (uint32_t c : out.children(i)) sum += nodes[c].sourceCount;
            if (sum != r.sourceCount)
                return fail(FileStatus::BadTree, "node " + std::to_string(i) + " lists " + std::to_string(r.sourceCount) +
                                                     " objects, its children " + std::to_string(sum));
            for (uint32_t o : out.sources(i)) {
                const uint32_t leaf = ownerLeaf[o];
                if (stamp[o] == i)
                    return fail(FileStatus::BadTree, "node " + std::to_string(i) + " lists object " +
                                                         std::to_string(o) + " twice");
                stamp[o] = i;
                if (enter[leaf] < enter[i] || enter[leaf] >= leave[i])
                    return fail(FileStatus::BadTree, "node " + std::to_string(i) + " lists object " + std::to_string(o) +
                                                         " that none of its leaves stands for");
            }
        }
        return FileStatus::Ok;
    }
};

FileStatus RuntimeFile::openMemory(const void* data, size_t size, RuntimeFile& out,
                                   std::string& message) {
    out = RuntimeFile();
    message.clear();
    if (data == nullptr) {
        message = "null buffer";
        return FileStatus::IoError;
    }
    RuntimeFile candidate;
    FileValidator validator{static_cast<const uint8_t*>(data), size, candidate, message};
    const FileStatus status = validator.run();
    if (status == FileStatus::Ok) out = std::move(candidate);
    return status;
}

FileStatus RuntimeFile::openFile(const std::string& path, RuntimeFile& out, std::string& message) {
    out = RuntimeFile();
    message.clear();
    auto mapping = std::make_unique<MappedFile>();
    if (!mapping->open(path, message)) return FileStatus::IoError;
    if (mapping->size() == 0) {
        message = path + ": empty file";
        return FileStatus::Truncated;
    }
    RuntimeFile candidate;
    FileValidator validator{mapping->data(), mapping->size(), candidate, message, mapping.get()};
    const FileStatus status = validator.run();
    if (status != FileStatus::Ok) {
        message = path + ": " + message;
        return status;
    }
    out = std::move(candidate);
    out.mapping_ = std::move(mapping);
    return status;
}

}  // namespace aggrelod::runtime
