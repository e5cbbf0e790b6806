// SPDX-License-Identifier: MIT
// Byte layout of the `.aglod` runtime file (docs/design.md §4), shared by the writer and the
// reader so they cannot drift apart. Everything little-endian.
//
//   offset  size  field
//   0       8     magic "AGGRELOD"
//   8       2     major version (2)    10  2  minor version (0)
//   12      4     section count
//   16      8     total size in bytes (a multiple of 32)
//   24      8     checksum: fileChecksum() of the whole file with this field read as 0
//   32      8     bake-settings hash
//   40      24    tool version, UTF-8, NUL padded (at least one NUL)
//   64      32 x section count: section table {u32 kind, u32 stride, u64 offset,
//                 u64 count, u64 byte size}, kinds 1..kSectionCount in order
//   then the sections, each at a 16-byte aligned offset, zero padded.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>

namespace aggrelod::runtime::layout {

constexpr char kMagic[8] = {'A', 'G', 'G', 'R', 'E', 'L', 'O', 'D'};
constexpr size_t kHeaderSize = 64;
constexpr size_t kSectionEntrySize = 32;
constexpr size_t kToolVersionSize = 24;
constexpr size_t kChecksumOffset = 24;
constexpr size_t kSectionAlign = 16;
constexpr size_t kTotalSizeMultiple = 32;  // lets the checksum run on whole 32-byte blocks

enum SectionKind : uint32_t {
    kNodes = 1,        // NodeRecord, stride 88
    kRoots = 2,        // u32 node index
    kChildIndices = 3, // u32 node index
    kSourceObjects = 4,// u32 object index
    kPositions = 5,    // 3 x f32, stride 12
    kIndices = 6,      // u32, relative to the node's first vertex
    kNameRanges = 7,   // {u32 offset, u32 length} into kNameBlob, stride 8
    kNameBlob = 8,     // UTF-8 bytes
    kNormals = 9,      // 3 x f32 unit normal per vertex, stride 12 (same count as kPositions)
    kColors = 10,      // RGBA8 per vertex, RGB sRGB-encoded, alpha linear (same count as kPositions)
};
constexpr uint32_t kSectionCount = 10;
constexpr uint32_t kSectionStride[kSectionCount + 1] = {0, 88, 4, 4, 4, 12, 4, 8, 1, 12, 4};
constexpr const char* kSectionName[kSectionCount + 1] = {
    "", "nodes", "roots", "child indices", "source objects", "positions", "indices",
    "name ranges", "name blob", "normals", "colors"};
/// A stored normal's length may differ from 1 by this much (float rounding of the bake).
constexpr float kNormalLengthTolerance = 1e-3f;

inline bool hostIsLittleEndian() {
    const uint32_t one = 1;
    unsigned char first;
    std::memcpy(&first, &one, 1);
    return first == 1;
}

inline uint64_t loadU64(const uint8_t* p) { uint64_t v; std::memcpy(&v, p, 8); return v; }
inline uint32_t loadU32(const uint8_t* p) { uint32_t v; std::memcpy(&v, p, 4); return v; }
inline uint16_t loadU16(const uint8_t* p) { uint16_t v; std::memcpy(&v, p, 2); return v; }

/// Checksum of `size` bytes (a multiple of 32): FNV-1a over 64-bit words in four interleaved
/// lanes, then the lanes folded by the same step. Each step is a bijection of the state, so
/// any change confined to one word (in particular any single-byte change) changes the result;
/// four lanes keep the multiplications independent (several GB/s, for a fast open).
/// The 8 bytes at `skipOffset` are read as zero (the checksum field itself). Resumable: add()
/// whole 32-byte blocks in file order, in as many calls as wanted.
class FileChecksum {
public:
    /// Bytes [at, at + size) of the file, at `data` (at and size multiples of 32).
    void add(const uint8_t* data, size_t at, size_t size, size_t skipOffset) {
        for (size_t i = 0; i + 32 <= size; i += 32) {
            for (int k = 0; k < 4; ++k) {
                const size_t offset = i + 8 * static_cast<size_t>(k);
                const uint64_t word = at + offset == skipOffset ? 0 : loadU64(data + offset);
                lane_[k] = (lane_[k] ^ word) * kPrime;
            }
        }
    }
    /// The checksum of a file of `size` bytes once all of them were added.
    uint64_t value(size_t size) const {
        uint64_t h = 0xcbf29ce484222325ull;
        for (uint64_t l : lane_) h = (h ^ l) * kPrime;
        return h ^ static_cast<uint64_t>(size);
    }

private:
    static constexpr uint64_t kPrime = 0x100000001b3ull;
    uint64_t lane_[4] = {0xcbf29ce484222325ull, 0x84222325cbf29ce4ull, 0x9ce484222325cbf2ull,
                         0x2325cbf29ce48422ull};
};

inline uint64_t fileChecksum(const uint8_t* data, size_t size, size_t skipOffset) {
    FileChecksum sum;
    sum.add(data, 0, size, skipOffset);
    return sum.value(size);
}

}  // namespace aggrelod::runtime::layout
