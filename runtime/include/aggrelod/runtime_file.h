// SPDX-License-Identifier: MIT
// aggrelod runtime: the `.aglod` runtime file, read in place (docs/design.md §4).
// A RuntimeFile views a memory-mapped file or a caller buffer; it never copies the arrays.
// Every count, stride, index range and the tree shape are validated once at open; a bad
// file is refused with a FileStatus and a message, never a crash. Standard library only.
#pragma once

#include <aggrelod/runtime_build.h>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

namespace aggrelod::runtime {

/// Format version written by writeRuntimeFile. A reader accepts only its own major version.
/// 2: per-vertex normals and colours (sections 9 and 10). 3.1: bundle levels (isBundleLevel),
/// which a 3.0 reader refuses as a bad level.
constexpr uint16_t kFormatMajor = 3;
constexpr uint16_t kFormatMinor = 1;

/// Why a file was refused (FileStatus::Ok when it was accepted).
enum class FileStatus : uint32_t {
    Ok = 0,
    IoError,           ///< cannot open / map the file
    WrongMagic,        ///< not an .aglod file
    WrongVersion,      ///< major version differs from kFormatMajor
    Truncated,         ///< fewer bytes than the header says (or than a header)
    ChecksumMismatch,  ///< content changed after writing
    BadSection,        ///< section table inconsistent (missing, overlapping, misaligned, bad stride)
    IndexOutOfRange,   ///< a range or index points outside its array
    BadTree,           ///< parents/children inconsistent, cycle, coverage, error or bounds not monotone
    BadValue,          ///< NaN / infinite / negative where not allowed
    Misaligned,        ///< caller buffer not 16-byte aligned
    UnsupportedHost,   ///< big-endian host (the format is little-endian, read in place)
};

/// Short English name of a status, e.g. "checksum mismatch".
const char* toString(FileStatus status);

/// A read-only array view (pointer + count) into the file.
template <class T>
struct Span {
    const T* data = nullptr;
    size_t size = 0;
    const T* begin() const { return data; }
    const T* end() const { return data + size; }
    const T& operator[](size_t i) const { return data[i]; }
    bool empty() const { return size == 0; }
};

class MappedFile;  // POSIX mmap or Windows MapViewOfFile, runtime/src/mapped_file.cpp

/// A validated `.aglod` file. Move-only; owns its mapping when opened from a path.
class RuntimeFile {
public:
    RuntimeFile();
    ~RuntimeFile();
    RuntimeFile(RuntimeFile&&) noexcept;
    RuntimeFile& operator=(RuntimeFile&&) noexcept;
    RuntimeFile(const RuntimeFile&) = delete;
    RuntimeFile& operator=(const RuntimeFile&) = delete;

    /// Maps `path` read-only and validates it. On failure `out` is left empty and
    /// `message` says what is wrong (e.g. "node 12: child 40 has parent 3").
    static FileStatus openFile(const std::string& path, RuntimeFile& out, std::string& message);

    /// Validates `size` bytes at `data` (16-byte aligned) and views them in place: the
    /// caller keeps the buffer alive and unchanged while `out` is used.
    static FileStatus openMemory(const void* data, size_t size, RuntimeFile& out,
                                 std::string& message);

    bool isOpen() const { return base_ != nullptr; }
    uint16_t versionMajor() const { return versionMajor_; }
    uint16_t versionMinor() const { return versionMinor_; }
    uint64_t settingsHash() const { return settingsHash_; }
    std::string_view toolVersion() const { return toolVersion_; }
    size_t byteSize() const { return byteSize_; }

    uint32_t nodeCount() const { return static_cast<uint32_t>(nodes_.size); }
    uint32_t objectCount() const { return static_cast<uint32_t>(nameRanges_.size / 2); }
    const NodeRecord& node(uint32_t i) const { return nodes_.data[i]; }
    Span<NodeRecord> nodes() const { return nodes_; }
    /// Nodes without parent, increasing.
    Span<uint32_t> roots() const { return roots_; }
    /// Children / original objects / vertices (xyz floats) / triangle indices of a node.
    Span<uint32_t> children(uint32_t node) const;
    Span<uint32_t> sources(uint32_t node) const;
    Span<float> vertices(uint32_t node) const;  ///< 3 floats per vertex, world units
    Span<uint32_t> triangles(uint32_t node) const;  ///< 3 per triangle, relative to node's vertices
    /// Unit outward normal per vertex of a node: 3 floats per vertex, as many vertices as
    /// vertices(). The bake smooths across edges whose faces' normals differ by at most 60
    /// degrees and splits the vertices of sharper edges and colour boundaries (docs/runtime.md).
    Span<float> normals(uint32_t node) const;
    /// Base colour per vertex of a node: 4 bytes per vertex (RGB sRGB-encoded, alpha linear;
    /// decodeColorSrgb8 gives linear RGBA), as many vertices as vertices().
    Span<uint8_t> colors(uint32_t node) const;
    bool isLeaf(uint32_t node) const { return nodes_.data[node].childCount == 0; }
    /// A simplified version of one object (level kObjectLodLevel), not an aggregate.
    bool isObjectLod(uint32_t node) const { return nodes_.data[node].level == kObjectLodLevel; }
    /// A coarser version of the aggregate below it (level kCoarserLevel), not a level of its own.
    bool isCoarser(uint32_t node) const { return nodes_.data[node].level == kCoarserLevel; }
    /// A bundle (level kBundleLevelFlag | k): the drawn versions of a level-k aggregate's
    /// children (or of a bake's several roots) merged into one mesh, not a level of its own.
    bool isBundle(uint32_t node) const { return isBundleLevel(nodes_.data[node].level); }
    /// The whole source-object array (NodeRecord::firstSource indexes it).
    Span<uint32_t> allSourceObjects() const { return sourceObjects_; }
    /// Name of original object `object` (< objectCount()), UTF-8.
    std::string_view objectName(uint32_t object) const;
    /// Largest number of nodes on a root-to-leaf path.
    uint32_t depth() const { return depth_; }

private:
    friend struct FileValidator;
    const uint8_t* base_ = nullptr;
    size_t byteSize_ = 0;
    std::unique_ptr<MappedFile> mapping_;
    uint16_t versionMajor_ = 0, versionMinor_ = 0;
    uint64_t settingsHash_ = 0;
    std::string toolVersion_;
    uint32_t depth_ = 0;
    Span<NodeRecord> nodes_;
    Span<uint32_t> roots_, childIndices_, sourceObjects_, indices_, nameRanges_;
    Span<float> positions_, normals_;
    Span<uint8_t> colors_;
    Span<char> nameBlob_;
};

}  // namespace aggrelod::runtime
