// SPDX-License-Identifier: MIT
// Writer of the `.aglod` runtime file (docs/design.md §4): BuildParams -> one little-endian
// blob with a 16-byte aligned section per array. The writer only lays bytes out; whether the
// hierarchy is consistent is decided by the reader's validator, run on the result, so the
// writer can never produce a file that the reader refuses.
#include <aggrelod/runtime_build.h>
#include <aggrelod/runtime_file.h>

#include "aglod_layout.h"

#include <algorithm>
#include <cmath>
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
    if (params.positions.size() % 3 != 0) {
        error = "positions: " + std::to_string(params.positions.size()) +
                " floats is not a multiple of 3";
        return false;
    }
    if (params.normals.size() != params.positions.size()) {
        error = "normals: " + std::to_string(params.normals.size()) + " floats for " +
                std::to_string(params.positions.size()) + " position floats (one normal per vertex)";
        return false;
    }
    if (params.colors.size() / 4 != params.positions.size() / 3 || params.colors.size() % 4 != 0) {
        error = "colors: " + std::to_string(params.colors.size()) + " bytes for " +
                std::to_string(params.positions.size() / 3) + " vertices (4 bytes per vertex)";
        return false;
    }
    if (params.toolVersion.size() >= kToolVersionSize) {
        error = "tool version '" + params.toolVersion + "' is longer than " +
                std::to_string(kToolVersionSize - 1) + " bytes";
        return false;
    }
    if (params.nodes.size() >= kMaxU32 || params.childIndices.size() > kMaxU32 ||
        params.sourceObjects.size() > kMaxU32 || params.positions.size() / 3 > kMaxU32 ||
        params.indices.size() > kMaxU32 || params.objectNames.size() > kMaxU32) {
        error = "an array has more than 2^32-1 elements";
        return false;
    }

    // Node records: the same fields as BuildNode, in the on-disk order.
    std::vector<NodeRecord> records(params.nodes.size());
    std::vector<uint32_t> roots;
    for (size_t i = 0; i < params.nodes.size(); ++i) {
        const BuildNode& b = params.nodes[i];
        NodeRecord& r = records[i];
        r.parent = b.parent;
        r.firstChild = b.firstChild;
        r.childCount = b.childCount;
        r.firstSource = b.firstSource;
        r.sourceCount = b.sourceCount;
        r.firstVertex = b.firstVertex;
        r.vertexCount = b.vertexCount;
        r.firstIndex = b.firstIndex;
        r.indexCount = b.indexCount;
        r.level = b.level;
        r.delta = b.delta;
        r.geometricError = b.geometricError;
        for (int k = 0; k < 3; ++k) {
            r.boundsMin[k] = b.boundsMin[k];
            r.boundsMax[k] = b.boundsMax[k];
            r.sphereCenter[k] = b.sphereCenter[k];
        }
        r.sphereRadius = b.sphereRadius;
        if (b.parent == kNoIndex) roots.push_back(static_cast<uint32_t>(i));
    }

    // Object names: {offset, length} pairs into one blob.
    std::vector<uint32_t> nameRanges;
    std::string blob;
    nameRanges.reserve(params.objectNames.size() * 2);
    for (const std::string& name : params.objectNames) {
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
        {records.data(), records.size()},
        {roots.data(), roots.size()},
        {params.childIndices.data(), params.childIndices.size()},
        {params.sourceObjects.data(), params.sourceObjects.size()},
        {params.positions.data(), params.positions.size() / 3},
        {params.indices.data(), params.indices.size()},
        {nameRanges.data(), nameRanges.size() / 2},
        {blob.data(), blob.size()},
        {params.normals.data(), params.normals.size() / 3},
        {params.colors.data(), params.colors.size() / 4},
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

namespace {
float srgbToLinear(float c) { return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f); }
float linearToSrgb(float c) { return c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f; }
uint8_t toByte(float unit) { return static_cast<uint8_t>(std::lround(unit * 255.0f)); }
float clampUnit(float v) { return v > 0.0f ? std::min(v, 1.0f) : 0.0f; }  // NaN -> 0
}  // namespace

void encodeColorSrgb8(const float linear[4], uint8_t out[4]) {
    for (int k = 0; k < 3; ++k) out[k] = toByte(linearToSrgb(clampUnit(linear[k])));
    out[3] = toByte(clampUnit(linear[3]));
}

void decodeColorSrgb8(const uint8_t encoded[4], float linear[4]) {
    for (int k = 0; k < 3; ++k) linear[k] = srgbToLinear(encoded[k] / 255.0f);
    linear[3] = encoded[3] / 255.0f;
}

}  // namespace aggrelod::runtime
