// SPDX-License-Identifier: MIT
// Writer of the `.aglod` runtime file (docs/design.md §4): BuildParams -> one little-endian
// blob with a 16-byte aligned section per array. The writer only lays bytes out; whether the
// hierarchy is consistent is decided by the reader's validator, run on the result, so the
// writer can never produce a file that the reader refuses.
#include <aggrelod/runtime_build.h>
#include <aggrelod/runtime_file.h>

#include "aglod_layout.h"

#include <algorithm>
#include <cstring>
#include <limits>

namespace aggrelod::runtime {

namespace {

size_t alignUp(size_t v, size_t a) { return (v + a - 1) / a * a; }

void storeU16(uint8_t* p, uint16_t v) { std::memcpy(p, &v, 2); }
void storeU32(uint8_t* p, uint32_t v) { std::memcpy(p, &v, 4); }
void storeU64(uint8_t* p, uint64_t v) { std::memcpy(p, &v, 8); }

struct SectionSource {
    const void* data;
    uint64_t count;
};

}  // namespace

bool writeRuntimeFile(const BuildParams& params, std::vector<uint8_t>& bytes, std::string& error) {
    using namespace layout;
    bytes.clear();
    if (!hostIsLittleEndian()) {
        error = "aglod writer: big-endian hosts are not supported";
        return false;
    }
    constexpr uint64_t kMaxU32 = std::numeric_limits<uint32_t>::max();
    // A null pointer with a non-zero count would be read from: refuse it.
    if ((!params.nodes && params.nodeCount) || (!params.childIndices && params.childIndexCount) ||
        (!params.sourceObjects && params.sourceObjectCount) || (!params.positions && params.positionCount) ||
        (!params.normals && params.normalCount) || (!params.colors && params.colorCount) ||
        (!params.indices && params.indexCount) || (!params.objectNames && params.objectCount)) {
        error = "an array has a count but no data";
        return false;
    }
    if (params.positionCount % 3 != 0) {
        error = "positions: " + std::to_string(params.positionCount) + " floats is not a multiple of 3";
        return false;
    }
    if (params.normalCount != params.positionCount) {
        error = "normals: " + std::to_string(params.normalCount) + " floats for " +
                std::to_string(params.positionCount) + " position floats (one normal per vertex)";
        return false;
    }
    if (params.colorCount / 4 != params.positionCount / 3 || params.colorCount % 4 != 0) {
        error = "colors: " + std::to_string(params.colorCount) + " bytes for " +
                std::to_string(params.positionCount / 3) + " vertices (4 bytes per vertex)";
        return false;
    }
    if (params.toolVersion.size() >= kToolVersionSize) {
        error = "tool version '" + std::string(params.toolVersion) + "' is longer than " +
                std::to_string(kToolVersionSize - 1) + " bytes";
        return false;
    }
    if (params.nodeCount >= kMaxU32 || params.childIndexCount > kMaxU32 || params.sourceObjectCount > kMaxU32 ||
        params.positionCount / 3 > kMaxU32 || params.indexCount > kMaxU32 || params.objectCount > kMaxU32) {
        error = "an array has more than 2^32-1 elements";
        return false;
    }

    // The node records are the file's own layout: written as given.
    std::vector<uint32_t> roots;
    for (size_t i = 0; i < params.nodeCount; ++i)
        if (params.nodes[i].parent == kNoIndex) roots.push_back(static_cast<uint32_t>(i));

    // Object names: {offset, length} pairs into one blob.
    std::vector<uint32_t> nameRanges;
    std::string blob;
    nameRanges.reserve(params.objectCount * 2);
    for (size_t i = 0; i < params.objectCount; ++i) {
        const std::string& name = params.objectNames[i];
        if (blob.size() + name.size() > kMaxU32) {
            error = "object names exceed 4 GiB";
            return false;
        }
        nameRanges.push_back(static_cast<uint32_t>(blob.size()));
        nameRanges.push_back(static_cast<uint32_t>(name.size()));
        blob += name;
    }

    const SectionSource sources[kSectionCount + 1] = {
        {nullptr, 0},
        {params.nodes, params.nodeCount},
        {roots.data(), roots.size()},
        {params.childIndices, params.childIndexCount},
        {params.sourceObjects, params.sourceObjectCount},
        {params.positions, params.positionCount / 3},
        {params.indices, params.indexCount},
        {nameRanges.data(), nameRanges.size() / 2},
        {blob.data(), blob.size()},
        {params.normals, params.normalCount / 3},
        {params.colors, params.colorCount / 4},
    };

    size_t offsets[kSectionCount + 1] = {};
    size_t cursor = kHeaderSize + kSectionEntrySize * kSectionCount;
    for (uint32_t s = 1; s <= kSectionCount; ++s) {
        cursor = alignUp(cursor, kSectionAlign);
        offsets[s] = cursor;
        cursor += sources[s].count * kSectionStride[s];
    }
    const size_t total = alignUp(cursor, kTotalSizeMultiple);
    bytes.assign(total, 0);
    uint8_t* out = bytes.data();

    std::memcpy(out, kMagic, sizeof(kMagic));
    storeU16(out + 8, kFormatMajor);
    storeU16(out + 10, kFormatMinor);
    storeU32(out + 12, kSectionCount);
    storeU64(out + 16, total);
    storeU64(out + 32, params.settingsHash);
    std::memcpy(out + 40, params.toolVersion.data(), params.toolVersion.size());
    for (uint32_t s = 1; s <= kSectionCount; ++s) {
        uint8_t* e = out + kHeaderSize + kSectionEntrySize * (s - 1);
        const uint64_t byteSize = sources[s].count * kSectionStride[s];
        storeU32(e, s);
        storeU32(e + 4, kSectionStride[s]);
        storeU64(e + 8, offsets[s]);
        storeU64(e + 16, sources[s].count);
        storeU64(e + 24, byteSize);
        if (byteSize) std::memcpy(out + offsets[s], sources[s].data, byteSize);
    }
    storeU64(out + kChecksumOffset, fileChecksum(out, total, kChecksumOffset));

    // The reader's validator is the single definition of a consistent hierarchy.
    RuntimeFile check;
    std::string message;
    const FileStatus status = RuntimeFile::openMemory(bytes.data(), bytes.size(), check, message);
    if (status != FileStatus::Ok) {
        error = std::string("inconsistent hierarchy (") + toString(status) + "): " + message;
        bytes.clear();
        return false;
    }
    return true;
}

}  // namespace aggrelod::runtime
