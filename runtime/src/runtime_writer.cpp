// SPDX-License-Identifier: MIT
// Writer of the `.aglod` runtime file (docs/design.md §4): BuildParams -> one little-endian
// blob with a 16-byte aligned section per array. The writer only lays bytes out; whether the
// hierarchy is consistent is decided by the reader's validator, run on the result, so the
// writer can never produce a file that the reader refuses.
#include <aggrelod/runtime_build.h>
#include <aggrelod/runtime_file.h>

#include "aglod_layout.h"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <iterator>
#include <limits>

namespace aggrelod::runtime {

namespace {

size_t alignUp(size_t v, size_t a) { return (v + a - 1) / a * a; }

void storeU16(uint8_t* p, uint16_t v) { std::memcpy(p, &v, 2); }
void storeU32(uint8_t* p, uint32_t v) { std::memcpy(p, &v, 4); }
void storeU64(uint8_t* p, uint64_t v) { std::memcpy(p, &v, 8); }

struct SectionSource {
    const void* data = nullptr;
    uint64_t count = 0;
    std::FILE* spill = nullptr;  ///< the section's bytes, from its start, instead of data
};

/// Where every section of a file for `params` goes; checks what the layout itself needs.
struct FileLayout {
    std::vector<uint32_t> roots;
    std::vector<uint32_t> nameRanges;  ///< {offset, length} per object name into `names`
    std::string names;
    SectionSource sources[layout::kSectionCount + 1] = {};
    size_t offsets[layout::kSectionCount + 1] = {};
    size_t total = 0;
    /// Magic, version, counts and the section table; the checksum field is 0.
    std::vector<uint8_t> header;
};

// A null pointer with a non-zero count would be read from.
bool checkPointers(const BuildParams& params, std::string& error) {
    if ((!params.nodes && params.nodeCount) || (!params.childIndices && params.childIndexCount) ||
        (!params.sourceObjects && params.sourceObjectCount) || (!params.positions && params.positionCount) ||
        (!params.normals && params.normalCount) || (!params.colors && params.colorCount) ||
        (!params.indices && params.indexCount) || (!params.objectNames && params.objectCount)) {
        error = "an array has a count but no data";
        return false;
    }
    return true;
}

/// Lays out a file for `params`; arrays whose data is null come from spill files the caller
/// sets in plan.sources afterwards (checkPointers refuses them for callers that give arrays).
bool planFile(const BuildParams& params, FileLayout& plan, std::string& error) {
    using namespace layout;
    if (!hostIsLittleEndian()) {
        error = "aglod writer: big-endian hosts are not supported";
        return false;
    }
    constexpr uint64_t kMaxU32 = std::numeric_limits<uint32_t>::max();
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
    for (size_t i = 0; i < params.nodeCount; ++i)
        if (params.nodes[i].parent == kNoIndex) plan.roots.push_back(static_cast<uint32_t>(i));

    // Object names: {offset, length} pairs into one blob.
    plan.nameRanges.reserve(params.objectCount * 2);
    for (size_t i = 0; i < params.objectCount; ++i) {
        const std::string& name = params.objectNames[i];
        if (plan.names.size() + name.size() > kMaxU32) {
            error = "object names exceed 4 GiB";
            return false;
        }
        plan.nameRanges.push_back(static_cast<uint32_t>(plan.names.size()));
        plan.nameRanges.push_back(static_cast<uint32_t>(name.size()));
        plan.names += name;
    }

    const SectionSource sources[kSectionCount + 1] = {
        {nullptr, 0},
        {params.nodes, params.nodeCount},
        {plan.roots.data(), plan.roots.size()},
        {params.childIndices, params.childIndexCount},
        {params.sourceObjects, params.sourceObjectCount},
        {params.positions, params.positionCount / 3},
        {params.indices, params.indexCount},
        {plan.nameRanges.data(), plan.nameRanges.size() / 2},
        {plan.names.data(), plan.names.size()},
        {params.normals, params.normalCount / 3},
        {params.colors, params.colorCount / 4},
    };
    std::copy(std::begin(sources), std::end(sources), plan.sources);

    size_t cursor = kHeaderSize + kSectionEntrySize * kSectionCount;
    for (uint32_t s = 1; s <= kSectionCount; ++s) {
        cursor = alignUp(cursor, kSectionAlign);
        plan.offsets[s] = cursor;
        cursor += plan.sources[s].count * kSectionStride[s];
    }
    plan.total = alignUp(cursor, kTotalSizeMultiple);

    plan.header.assign(kHeaderSize + kSectionEntrySize * kSectionCount, 0);
    uint8_t* out = plan.header.data();
    std::memcpy(out, kMagic, sizeof(kMagic));
    storeU16(out + 8, kFormatMajor);
    storeU16(out + 10, kFormatMinor);
    storeU32(out + 12, kSectionCount);
    storeU64(out + 16, plan.total);
    storeU64(out + 32, params.settingsHash);
    std::memcpy(out + 40, params.toolVersion.data(), params.toolVersion.size());
    for (uint32_t s = 1; s <= kSectionCount; ++s) {
        uint8_t* e = out + kHeaderSize + kSectionEntrySize * (s - 1);
        storeU32(e, s);
        storeU32(e + 4, kSectionStride[s]);
        storeU64(e + 8, plan.offsets[s]);
        storeU64(e + 16, plan.sources[s].count);
        storeU64(e + 24, plan.sources[s].count * kSectionStride[s]);
    }
    return true;
}

/// Calls put(data, byteCount) for the file's bytes in order (checksum field 0). False when a
/// spill file cannot be read back whole.
template <typename Put>
bool emitFile(const FileLayout& plan, Put&& put) {
    using namespace layout;
    static const uint8_t zeros[kSectionAlign > kTotalSizeMultiple ? kSectionAlign : kTotalSizeMultiple] = {};
    size_t at = plan.header.size();
    put(plan.header.data(), at);
    std::vector<uint8_t> buffer;
    for (uint32_t s = 1; s <= kSectionCount; ++s) {
        put(zeros, plan.offsets[s] - at);
        const size_t byteSize = plan.sources[s].count * kSectionStride[s];
        if (std::FILE* spill = plan.sources[s].spill) {
            buffer.resize(size_t(4) << 20);
            if (std::fflush(spill) != 0 || std::fseek(spill, 0, SEEK_SET) != 0) return false;
            for (size_t left = byteSize; left > 0;) {
                const size_t n = std::min(left, buffer.size());
                if (std::fread(buffer.data(), 1, n, spill) != n) return false;
                put(buffer.data(), n);
                left -= n;
            }
        } else if (byteSize) {
            put(plan.sources[s].data, byteSize);
        }
        at = plan.offsets[s] + byteSize;
    }
    put(zeros, plan.total - at);
    return true;
}

/// layout::fileChecksum over bytes given in pieces of any size (the checksum field given as
/// 0): whole 32-byte blocks go to layout::FileChecksum.
class StreamChecksum {
public:
    void add(const void* data, size_t size) {
        const auto* p = static_cast<const uint8_t*>(data);
        while (size > 0) {
            const size_t n = std::min(size, sizeof(block_) - filled_);
            std::memcpy(block_ + filled_, p, n);
            filled_ += n;
            p += n;
            size -= n;
            if (filled_ == sizeof(block_)) {
                sum_.add(block_, total_, sizeof(block_), SIZE_MAX);  // nothing to skip: the field is 0
                filled_ = 0;
                total_ += sizeof(block_);
            }
        }
    }
    uint64_t value() const { return sum_.value(total_ + filled_); }

private:
    layout::FileChecksum sum_;
    uint8_t block_[32] = {};
    size_t filled_ = 0;
    uint64_t total_ = 0;
};

}  // namespace

bool writeRuntimeFile(const BuildParams& params, std::vector<uint8_t>& bytes, std::string& error) {
    using namespace layout;
    bytes.clear();
    FileLayout plan;
    if (!checkPointers(params, error) || !planFile(params, plan, error)) return false;
    bytes.resize(plan.total);
    uint8_t* cursor = bytes.data();
    emitFile(plan, [&](const void* data, size_t size) {
        if (size) std::memcpy(cursor, data, size);
        cursor += size;
    });
    storeU64(bytes.data() + kChecksumOffset, fileChecksum(bytes.data(), plan.total, kChecksumOffset));

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

/// Writes the file `plan` lays out to `path`; false (nothing left at `path`) on failure.
bool writePlanned(const FileLayout& plan, const std::string& path, std::string& error) {
    using namespace layout;
    std::FILE* f = std::fopen(path.c_str(), "wb");
    if (!f) {
        error = path + ": cannot open for writing";
        return false;
    }
    StreamChecksum checksum;
    bool written = true;
    const bool spillsRead = emitFile(plan, [&](const void* data, size_t size) {
        checksum.add(data, size);
        if (written && size) written = std::fwrite(data, 1, size, f) == size;
    });
    uint8_t sum[8];
    storeU64(sum, checksum.value());
    written = written && spillsRead && std::fseek(f, long(kChecksumOffset), SEEK_SET) == 0 &&
              std::fwrite(sum, 1, 8, f) == 8;
    const bool closed = std::fclose(f) == 0;
    if (!written || !closed) {
        std::remove(path.c_str());
        error = path + (spillsRead ? ": write failed (disk full?)" : ": its spill files could not be read back");
        return false;
    }
    return true;
}

/// The reader's validator is the single definition of a consistent hierarchy.
bool checkWritten(const std::string& path, std::string& error) {
    RuntimeFile check;
    std::string message;
    const FileStatus status = RuntimeFile::openFile(path, check, message);
    if (status != FileStatus::Ok) {
        std::remove(path.c_str());
        error = std::string("inconsistent hierarchy (") + toString(status) + "): " + message;
        return false;
    }
    return true;
}

}  // namespace

bool writeRuntimeFile(BuildArrays&& arrays, const std::string& path, std::string& error) {
    {
        FileLayout plan;
        if (!checkPointers(arrays.params(), error) || !planFile(arrays.params(), plan, error)) return false;
        if (!writePlanned(plan, path, error)) return false;
    }
    arrays = BuildArrays{};  // released before the file is read back
    return checkWritten(path, error);
}

// --- RuntimeFileStreamWriter ---------------------------------------------------------------

struct RuntimeFileStreamWriter::State {
    std::string path;
    BuildArrays arrays;  ///< everything but the spilled positions, normals, colors and indices
    /// Spill files beside `path`, in the order positions, indices, normals, colors.
    std::string spillPaths[4];
    std::FILE* spills[4] = {nullptr, nullptr, nullptr, nullptr};
    uint64_t vertexCount = 0, indexCount = 0;
    bool failed = false, finished = false;  ///< writing and checking remove `path` when they fail

    void closeSpills() {
        for (int k = 0; k < 4; ++k) {
            if (spills[k]) std::fclose(spills[k]);
            spills[k] = nullptr;
            if (!spillPaths[k].empty()) std::remove(spillPaths[k].c_str());
        }
    }
    ~State() { closeSpills(); }
};

RuntimeFileStreamWriter::RuntimeFileStreamWriter() : state_(nullptr) {}
RuntimeFileStreamWriter::~RuntimeFileStreamWriter() { delete state_; }

bool RuntimeFileStreamWriter::open(const std::string& path, std::vector<std::string> objectNames,
                                   uint64_t settingsHash, std::string toolVersion, std::string& error) {
    delete state_;
    state_ = new State;
    state_->arrays.objectNames = std::move(objectNames);
    state_->arrays.settingsHash = settingsHash;
    state_->arrays.toolVersion = std::move(toolVersion);
    const char* suffixes[4] = {".positions.spill", ".indices.spill", ".normals.spill", ".colors.spill"};
    for (int k = 0; k < 4; ++k) {
        state_->spillPaths[k] = path + suffixes[k];
        state_->spills[k] = std::fopen(state_->spillPaths[k].c_str(), "w+b");
        if (!state_->spills[k]) {
            error = state_->spillPaths[k] + ": cannot open for writing";
            state_->spillPaths[k].clear();
            state_->failed = true;
            return false;
        }
    }
    state_->path = path;
    return true;
}

bool RuntimeFileStreamWriter::addNode(NodeRecord record, const uint32_t* children, size_t childCount,
                                      const uint32_t* sources, size_t sourceCount, const float* positions,
                                      const float* normals, const uint8_t* colors, size_t vertexCount,
                                      const uint32_t* indices, size_t indexCount, std::string& error) {
    if (!state_ || state_->failed || state_->finished) {
        error = "aglod stream writer: addNode without a successful open";
        return false;
    }
    State& st = *state_;
    if ((!children && childCount) || (!sources && sourceCount) ||
        (vertexCount && (!positions || !normals || !colors)) || (!indices && indexCount)) {
        error = "node " + std::to_string(st.arrays.nodes.size()) + ": an array has a count but no data";
        st.failed = true;
        return false;
    }
    constexpr uint64_t kMaxU32 = std::numeric_limits<uint32_t>::max();
    if (st.arrays.nodes.size() >= kMaxU32 || st.arrays.childIndices.size() + childCount > kMaxU32 ||
        st.arrays.sourceObjects.size() + sourceCount > kMaxU32 || st.vertexCount + vertexCount > kMaxU32 ||
        st.indexCount + indexCount > kMaxU32) {
        error = "an array has more than 2^32-1 elements";
        st.failed = true;
        return false;
    }
    record.firstChild = uint32_t(st.arrays.childIndices.size());
    record.childCount = uint32_t(childCount);
    record.firstSource = uint32_t(st.arrays.sourceObjects.size());
    record.sourceCount = uint32_t(sourceCount);
    record.firstVertex = uint32_t(st.vertexCount);
    record.vertexCount = uint32_t(vertexCount);
    record.firstIndex = uint32_t(st.indexCount);
    record.indexCount = uint32_t(indexCount);
    st.arrays.nodes.push_back(record);
    st.arrays.childIndices.insert(st.arrays.childIndices.end(), children, children + childCount);
    st.arrays.sourceObjects.insert(st.arrays.sourceObjects.end(), sources, sources + sourceCount);
    const struct {
        const void* data;
        size_t bytes;
    } parts[4] = {{positions, 12 * vertexCount}, {indices, 4 * indexCount}, {normals, 12 * vertexCount},
                  {colors, 4 * vertexCount}};
    for (int k = 0; k < 4; ++k)
        if (parts[k].bytes && std::fwrite(parts[k].data, 1, parts[k].bytes, st.spills[k]) != parts[k].bytes) {
            error = st.spillPaths[k] + ": write failed (disk full?)";
            st.failed = true;
            return false;
        }
    st.vertexCount += vertexCount;
    st.indexCount += indexCount;
    return true;
}

bool RuntimeFileStreamWriter::finish(std::string& error) {
    if (!state_ || state_->failed || state_->finished) {
        error = "aglod stream writer: finish without a successful open";
        return false;
    }
    State& st = *state_;
    BuildParams params = st.arrays.params();
    params.positionCount = params.normalCount = 3 * size_t(st.vertexCount);
    params.colorCount = 4 * size_t(st.vertexCount);
    params.indexCount = size_t(st.indexCount);
    FileLayout plan;
    st.failed = true;  // until written and checked
    if (!planFile(params, plan, error)) return false;
    plan.sources[layout::kPositions].spill = st.spills[0];
    plan.sources[layout::kIndices].spill = st.spills[1];
    plan.sources[layout::kNormals].spill = st.spills[2];
    plan.sources[layout::kColors].spill = st.spills[3];
    if (!writePlanned(plan, st.path, error)) return false;
    st.closeSpills();
    st.arrays = BuildArrays{};
    if (!checkWritten(st.path, error)) return false;
    st.failed = false;
    st.finished = true;
    return true;
}

}  // namespace aggrelod::runtime
