// SPDX-License-Identifier: MIT
// The `.aglod` runtime file (docs/design.md §4): round trip of the writer and the in-place
// reader, refusal of inconsistent hierarchies by the writer, and refusal of corrupt bytes by
// the reader (every single-byte change of the header and section table, truncations, forged
// tables with a recomputed checksum). Built and run under AddressSanitizer
// (aggrelod_runtime_asan_tests), so an out-of-bounds read during validation fails the suite.
#include <aggrelod/runtime_build.h>
#include <aggrelod/runtime_file.h>

#include "../../runtime/src/aglod_layout.h"
#include "synthetic_hierarchy.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <memory>
#include <set>

using namespace aggrelod::runtime;
using aggrelod::testing::makeSyntheticHierarchy;

namespace {

std::vector<uint8_t> writeOrDie(const BuildArrays& p) {
    std::vector<uint8_t> bytes;
    std::string error;
    EXPECT_TRUE(writeRuntimeFile(p, bytes, error)) << error;
    return bytes;
}

// A heap copy of exactly `size` bytes, so that ASan flags any read past the end.
struct ExactBuffer {
    std::unique_ptr<uint8_t[]> data;
    size_t size;
    ExactBuffer(const uint8_t* src, size_t n) : data(new uint8_t[n ? n : 1]), size(n) {
        if (n) std::memcpy(data.get(), src, n);
    }
};

FileStatus openCopy(const std::vector<uint8_t>& bytes, size_t size, std::string& message) {
    ExactBuffer copy(bytes.data(), size);
    RuntimeFile file;
    return RuntimeFile::openMemory(copy.data.get(), copy.size, file, message);
}

void resign(std::vector<uint8_t>& bytes) {
    using namespace aggrelod::runtime::layout;
    const uint64_t sum = fileChecksum(bytes.data(), bytes.size(), kChecksumOffset);
    std::memcpy(bytes.data() + kChecksumOffset, &sum, 8);
}

}  // namespace

TEST(RuntimeFormat, RoundTripKeepsEveryField) {
    const BuildArrays p = makeSyntheticHierarchy(300, 7, 3, 2);
    const std::vector<uint8_t> bytes = writeOrDie(p);
    ASSERT_EQ(bytes.size() % 32, 0u);
    RuntimeFile file;
    std::string message;
    ASSERT_EQ(RuntimeFile::openMemory(bytes.data(), bytes.size(), file, message), FileStatus::Ok) << message;
    EXPECT_EQ(file.versionMajor(), kFormatMajor);
    EXPECT_EQ(file.settingsHash(), p.settingsHash);
    EXPECT_EQ(file.toolVersion(), p.toolVersion);
    ASSERT_EQ(file.nodeCount(), p.nodes.size());
    ASSERT_EQ(file.objectCount(), p.objectNames.size());
    std::vector<uint32_t> roots;
    for (uint32_t i = 0; i < p.nodes.size(); ++i) {
        const NodeRecord& b = p.nodes[i];
        const NodeRecord& r = file.node(i);
        EXPECT_EQ(r.parent, b.parent);
        EXPECT_EQ(r.level, b.level);
        EXPECT_EQ(r.geometricError, b.geometricError);
        EXPECT_EQ(r.delta, b.delta);
        EXPECT_EQ(r.sphereRadius, b.sphereRadius);
        for (int k = 0; k < 3; ++k) {
            EXPECT_EQ(r.boundsMin[k], b.boundsMin[k]);
            EXPECT_EQ(r.boundsMax[k], b.boundsMax[k]);
            EXPECT_EQ(r.sphereCenter[k], b.sphereCenter[k]);
        }
        ASSERT_EQ(file.children(i).size, b.childCount);
        for (uint32_t c = 0; c < b.childCount; ++c) EXPECT_EQ(file.children(i)[c], p.childIndices[b.firstChild + c]);
        ASSERT_EQ(file.sources(i).size, b.sourceCount);
        for (uint32_t s = 0; s < b.sourceCount; ++s) EXPECT_EQ(file.sources(i)[s], p.sourceObjects[b.firstSource + s]);
        ASSERT_EQ(file.vertices(i).size, 3u * b.vertexCount);
        for (uint32_t v = 0; v < 3 * b.vertexCount; ++v) EXPECT_EQ(file.vertices(i)[v], p.positions[3 * b.firstVertex + v]);
        ASSERT_EQ(file.normals(i).size, 3u * b.vertexCount);
        for (uint32_t v = 0; v < 3 * b.vertexCount; ++v) EXPECT_EQ(file.normals(i)[v], p.normals[3 * b.firstVertex + v]);
        ASSERT_EQ(file.colors(i).size, 4u * b.vertexCount);
        for (uint32_t v = 0; v < 4 * b.vertexCount; ++v) EXPECT_EQ(file.colors(i)[v], p.colors[4 * b.firstVertex + v]);
        ASSERT_EQ(file.triangles(i).size, b.indexCount);
        for (uint32_t t = 0; t < b.indexCount; ++t) EXPECT_EQ(file.triangles(i)[t], p.indices[b.firstIndex + t]);
        if (b.parent == kNoIndex) roots.push_back(i);
    }
    ASSERT_EQ(file.roots().size, roots.size());
    for (size_t i = 0; i < roots.size(); ++i) EXPECT_EQ(file.roots()[i], roots[i]);
    for (uint32_t o = 0; o < file.objectCount(); ++o) EXPECT_EQ(file.objectName(o), p.objectNames[o]);
    EXPECT_GE(file.depth(), 5u);  // 150 objects per root, branching 3
}

TEST(RuntimeFormat, WriterIsDeterministicAndFileOpensFromDisk) {
    const BuildArrays p = makeSyntheticHierarchy(200, 3);
    const std::vector<uint8_t> a = writeOrDie(p), b = writeOrDie(p);
    EXPECT_EQ(a, b);
    const std::string path = std::string(AGGRELOD_TEST_TMP) + "/roundtrip.aglod";
    {
        std::ofstream out(path, std::ios::binary);
        out.write(reinterpret_cast<const char*>(a.data()), static_cast<std::streamsize>(a.size()));
    }
    RuntimeFile file;
    std::string message;
    ASSERT_EQ(RuntimeFile::openFile(path, file, message), FileStatus::Ok) << message;
    EXPECT_EQ(file.nodeCount(), p.nodes.size());
    EXPECT_EQ(file.byteSize(), a.size());
    RuntimeFile moved = std::move(file);  // the mapping moves with the file
    EXPECT_EQ(moved.objectName(5), "box5");
    EXPECT_EQ(RuntimeFile::openFile(path + ".missing", file, message), FileStatus::IoError);
    EXPECT_NE(message.find("roundtrip.aglod.missing"), std::string::npos) << message;
    { std::ofstream empty(path + ".empty"); }
    EXPECT_EQ(RuntimeFile::openFile(path + ".empty", file, message), FileStatus::Truncated);
    std::remove(path.c_str());
    std::remove((path + ".empty").c_str());
}

// The file written straight to disk is the image writeRuntimeFile gives in memory, for
// hierarchies of several sizes (sections of every length modulo the checksum's 32-byte
// blocks); the arrays are consumed; a refused hierarchy leaves no file.
TEST(RuntimeFormat, FileWrittenStraightToDiskIsTheSameImage) {
    const std::string path = std::string(AGGRELOD_TEST_TMP) + "/streamed.aglod";
    for (int objects : {1, 7, 40, 333}) {
        BuildArrays p = makeSyntheticHierarchy(objects, 3 + objects % 5, 3, 2);
        const std::vector<uint8_t> image = writeOrDie(p);
        std::string error;
        ASSERT_TRUE(writeRuntimeFile(std::move(p), path, error)) << objects << ": " << error;
        EXPECT_TRUE(p.nodes.empty() && p.positions.empty() && p.objectNames.empty()) << objects;
        std::ifstream in(path, std::ios::binary);
        const std::vector<uint8_t> written((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        EXPECT_EQ(written, image) << objects;
    }
    BuildArrays bad = makeSyntheticHierarchy(40, 2);
    bad.sourceObjects[0] = 9999;
    std::string error;
    std::remove(path.c_str());
    EXPECT_FALSE(writeRuntimeFile(std::move(bad), path, error));
    EXPECT_NE(error.find("index out of range"), std::string::npos) << error;
    EXPECT_FALSE(std::ifstream(path).good()) << "a refused hierarchy left " << path;
    EXPECT_FALSE(writeRuntimeFile(makeSyntheticHierarchy(5, 1), std::string(AGGRELOD_TEST_TMP) + "/no/such/dir/x.aglod", error));
    EXPECT_NE(error.find("cannot open"), std::string::npos) << error;
}

TEST(RuntimeFormat, SectionsAreAlignedAndLittleEndianHeader) {
    const std::vector<uint8_t> bytes = writeOrDie(makeSyntheticHierarchy(50, 1));
    EXPECT_EQ(std::memcmp(bytes.data(), "AGGRELOD", 8), 0);
    uint64_t total = 0;
    std::memcpy(&total, bytes.data() + 16, 8);
    EXPECT_EQ(total, bytes.size());
    for (uint32_t s = 0; s < aggrelod::runtime::layout::kSectionCount; ++s) {
        uint64_t offset = 0;
        std::memcpy(&offset, bytes.data() + 64 + 32 * s + 8, 8);
        EXPECT_EQ(offset % 16, 0u) << "section " << s + 1;
    }
}

TEST(RuntimeFormat, WriterRefusesInconsistentHierarchies) {
    const BuildArrays good = makeSyntheticHierarchy(40, 2);
    struct Case {
        const char* what;
        void (*breakIt)(BuildArrays&);
        const char* expected;
    };
    const Case cases[] = {
        {"child with another parent", [](BuildArrays& p) { p.nodes[p.childIndices[0]].parent = p.childIndices[1]; }, "bad tree"},
        {"source out of range", [](BuildArrays& p) { p.sourceObjects[0] = 9999; }, "index out of range"},
        {"error not monotone", [](BuildArrays& p) { p.nodes[0].geometricError = 1e6f; }, "bad tree"},
        {"child outside parent", [](BuildArrays& p) { p.nodes[0].boundsMax[0] += 1e4f; p.nodes[0].sphereCenter[0] += 1e4f; }, "bad tree"},
        {"triangle index too big", [](BuildArrays& p) { p.indices[0] = 100; }, "index out of range"},
        {"NaN radius", [](BuildArrays& p) { p.nodes[1].sphereRadius = std::nanf(""); }, "bad value"},
        {"object in no leaf", [](BuildArrays& p) { p.objectNames.push_back("orphan"); }, "bad tree"},
        {"cycle", [](BuildArrays& p) {
             // Make the root a child of its first child: no parentless node is left.
             const uint32_t root = static_cast<uint32_t>(p.nodes.size() - 1);
             p.nodes[root].parent = p.childIndices[p.nodes[root].firstChild];
         }, "bad tree"},
        {"child range past the array", [](BuildArrays& p) { p.nodes.back().firstChild = 1u << 30; }, "index out of range"},
        {"NaN normal", [](BuildArrays& p) { p.normals[7] = std::nanf(""); }, "bad value"},
        {"infinite normal", [](BuildArrays& p) { p.normals[3] = INFINITY; }, "bad value"},
        {"normal not of unit length", [](BuildArrays& p) { p.normals[0] *= 1.01f, p.normals[1] *= 1.01f, p.normals[2] *= 1.01f; }, "bad value"},
        {"zero normal", [](BuildArrays& p) { std::fill(p.normals.end() - 3, p.normals.end(), 0.0f); }, "bad value"},
        {"one normal missing", [](BuildArrays& p) { p.normals.resize(p.normals.size() - 3); }, "normals"},
        {"one colour missing", [](BuildArrays& p) { p.colors.resize(p.colors.size() - 4); }, "colors"},
        {"leaf with an aggregate level", [](BuildArrays& p) { p.nodes[0].level = 0; }, "bad value"},
        {"inner node with the leaf level", [](BuildArrays& p) { p.nodes.back().level = kLeafLevel; }, "bad value"},
        {"per-object LOD of several objects", [](BuildArrays& p) { p.nodes.back().level = kObjectLodLevel; }, "bad value"},
        {"level out of range", [](BuildArrays& p) { p.nodes.back().level = kMaxAggregateLevel; }, "bad value"},
        {"coarser version with two children", [](BuildArrays& p) { p.nodes.back().level = kCoarserLevel; }, "coarser version"},
        {"bundle of a level out of range", [](BuildArrays& p) { p.nodes.back().level = kBundleLevelFlag | kMaxAggregateLevel; }, "bad value"},
        {"bundle of level 0 above aggregates", [](BuildArrays& p) { p.nodes.back().level = kBundleLevelFlag; }, "bad tree"},
    };
    for (const Case& c : cases) {
        BuildArrays p = good;
        c.breakIt(p);
        std::vector<uint8_t> bytes;
        std::string error;
        EXPECT_FALSE(writeRuntimeFile(p, bytes, error)) << c.what;
        EXPECT_NE(error.find(c.expected), std::string::npos) << c.what << ": " << error;
        EXPECT_TRUE(bytes.empty()) << c.what;
    }
}

TEST(RuntimeFormat, EverySingleByteChangeOfHeaderAndTableIsRefused) {
    const std::vector<uint8_t> good = writeOrDie(makeSyntheticHierarchy(60, 4));
    const size_t tableEnd = 64 + 32 * aggrelod::runtime::layout::kSectionCount;
    std::set<FileStatus> seen;
    for (size_t at = 0; at < tableEnd; ++at) {
        for (int delta : {1, 0x80, 0xFF}) {
            std::vector<uint8_t> bad = good;
            bad[at] = static_cast<uint8_t>(bad[at] + delta);
            std::string message;
            const FileStatus status = openCopy(bad, bad.size(), message);
            ASSERT_NE(status, FileStatus::Ok) << "byte " << at << " +" << delta;
            EXPECT_FALSE(message.empty());
            seen.insert(status);
        }
    }
    EXPECT_TRUE(seen.count(FileStatus::WrongMagic));
    EXPECT_TRUE(seen.count(FileStatus::WrongVersion));
    EXPECT_TRUE(seen.count(FileStatus::Truncated));
    EXPECT_TRUE(seen.count(FileStatus::ChecksumMismatch));
}

TEST(RuntimeFormat, TruncationAtHundredOffsetsIsRefused) {
    const std::vector<uint8_t> good = writeOrDie(makeSyntheticHierarchy(120, 5));
    for (int i = 0; i < 100; ++i) {
        const size_t size = good.size() * static_cast<size_t>(i) / 100;  // 0 .. 99 % of the file
        std::string message;
        const FileStatus status = openCopy(good, size, message);
        EXPECT_EQ(status, FileStatus::Truncated) << size << " bytes: " << message;
    }
    std::string message;
    EXPECT_EQ(openCopy(good, good.size() - 1, message), FileStatus::Truncated);
}

TEST(RuntimeFormat, ForgedContentWithValidChecksumIsRefused) {
    // An attacker (or a writer bug) can recompute the checksum: the structural checks must
    // still hold. Single-byte changes of the table with a valid checksum, then of the nodes.
    const std::vector<uint8_t> good = writeOrDie(makeSyntheticHierarchy(60, 6));
    const size_t tableEnd = 64 + 32 * aggrelod::runtime::layout::kSectionCount;
    int refused = 0, accepted = 0;
    for (size_t at = 12; at < tableEnd; ++at) {
        if (at >= 24 && at < 64) continue;  // checksum, settings hash, tool version: free fields
        std::vector<uint8_t> bad = good;
        bad[at] ^= 0x40;
        resign(bad);
        std::string message;
        const FileStatus status = openCopy(bad, bad.size(), message);
        status == FileStatus::Ok ? ++accepted : ++refused;
    }
    EXPECT_EQ(accepted, 0);
    uint64_t nodesOffset = 0;
    std::memcpy(&nodesOffset, good.data() + 64 + 8, 8);
    // Parent, child range, source range, vertex range and index range of every node.
    for (uint32_t node = 0; node < 60; ++node) {
        for (size_t field = 0; field < 9; ++field) {
            std::vector<uint8_t> bad = good;
            bad[nodesOffset + 88 * node + 4 * field + 3] ^= 0x10;  // +2^28 on a u32 field
            resign(bad);
            std::string message;
            const FileStatus status = openCopy(bad, bad.size(), message);
            EXPECT_TRUE(status == FileStatus::IndexOutOfRange || status == FileStatus::BadTree ||
                        status == FileStatus::BadValue)
                << "node " << node << " field " << field << ": " << toString(status) << " " << message;
        }
    }
}

// Offset, count and stride of section `kind` as the table states them.
struct SectionEntry {
    uint64_t offset, count;
    uint32_t stride;
};
SectionEntry sectionEntry(const std::vector<uint8_t>& bytes, uint32_t kind) {
    SectionEntry e{};
    const uint8_t* at = bytes.data() + 64 + 32 * (kind - 1);
    std::memcpy(&e.stride, at + 4, 4);
    std::memcpy(&e.offset, at + 8, 8);
    std::memcpy(&e.count, at + 16, 8);
    return e;
}

TEST(RuntimeFormat, NormalsAndColorsSectionsAreOnePerVertex) {
    using namespace aggrelod::runtime::layout;
    const BuildArrays p = makeSyntheticHierarchy(30, 9);
    const std::vector<uint8_t> bytes = writeOrDie(p);
    const SectionEntry positions = sectionEntry(bytes, kPositions), normals = sectionEntry(bytes, kNormals),
                       colors = sectionEntry(bytes, kColors);
    EXPECT_EQ(normals.stride, 12u);
    EXPECT_EQ(colors.stride, 4u);
    EXPECT_EQ(normals.count, positions.count);
    EXPECT_EQ(colors.count, positions.count);
    EXPECT_EQ(positions.count, p.positions.size() / 3);
    // The bytes in place: little-endian floats, then RGBA bytes.
    EXPECT_EQ(std::memcmp(bytes.data() + normals.offset, p.normals.data(), 4 * p.normals.size()), 0);
    EXPECT_EQ(std::memcmp(bytes.data() + colors.offset, p.colors.data(), p.colors.size()), 0);
    uint16_t major = 0;
    std::memcpy(&major, bytes.data() + 8, 2);
    EXPECT_EQ(major, kFormatMajor);
}

TEST(RuntimeFormat, ForgedNormalsAndColorSectionsAreRefused) {
    // With a recomputed checksum: bad values in the normals, and counts or strides of the new
    // sections that disagree with the positions.
    using namespace aggrelod::runtime::layout;
    const std::vector<uint8_t> good = writeOrDie(makeSyntheticHierarchy(40, 10));
    const SectionEntry normals = sectionEntry(good, kNormals);
    const float bad[] = {std::nanf(""), INFINITY, -INFINITY, 1.5f, -2.0f, 1e30f};
    const uint64_t vertices = normals.count;
    for (uint64_t v : {uint64_t(0), vertices / 2, vertices - 1}) {
        for (int k = 0; k < 3; ++k) {
            for (float value : bad) {
                std::vector<uint8_t> forged = good;
                std::memcpy(forged.data() + normals.offset + 12 * v + 4 * k, &value, 4);
                resign(forged);
                std::string message;
                EXPECT_EQ(openCopy(forged, forged.size(), message), FileStatus::BadValue)
                    << "vertex " << v << " component " << k << " = " << value << ": " << message;
                EXPECT_NE(message.find("normal"), std::string::npos) << message;
            }
        }
    }
    {
        std::vector<uint8_t> forged = good;
        std::memset(forged.data() + normals.offset + 12 * (vertices / 3), 0, 12);
        resign(forged);
        std::string message;
        EXPECT_EQ(openCopy(forged, forged.size(), message), FileStatus::BadValue) << "zero normal: " << message;
    }
    // Count fields: one fewer / one more vertex (the byte size follows, so only the
    // per-vertex rule can refuse it).
    for (uint32_t kind : {kNormals, kColors}) {
        for (int64_t change : {-1, 1}) {
            std::vector<uint8_t> forged = good;
            const SectionEntry e = sectionEntry(forged, kind);
            const uint64_t count = e.count + change, byteSize = count * e.stride;
            std::memcpy(forged.data() + 64 + 32 * (kind - 1) + 16, &count, 8);
            std::memcpy(forged.data() + 64 + 32 * (kind - 1) + 24, &byteSize, 8);
            resign(forged);
            std::string message;
            EXPECT_EQ(openCopy(forged, forged.size(), message), FileStatus::BadSection) << kind << " " << change << ": " << message;
        }
        // Another stride.
        std::vector<uint8_t> forged = good;
        const uint32_t stride = kind == kNormals ? 6 : 8;
        std::memcpy(forged.data() + 64 + 32 * (kind - 1) + 4, &stride, 4);
        resign(forged);
        std::string message;
        EXPECT_EQ(openCopy(forged, forged.size(), message), FileStatus::BadSection) << message;
    }
    // A file of the previous major version (no normals or colours) is refused by version.
    std::vector<uint8_t> old = good;
    const uint16_t one = 1;
    std::memcpy(old.data() + 8, &one, 2);
    resign(old);
    std::string message;
    EXPECT_EQ(openCopy(old, old.size(), message), FileStatus::WrongVersion) << message;
}

TEST(RuntimeFormat, TruncationInsideTheNewSectionsIsRefused) {
    using namespace aggrelod::runtime::layout;
    const std::vector<uint8_t> good = writeOrDie(makeSyntheticHierarchy(40, 11));
    for (uint32_t kind : {kNormals, kColors}) {
        const SectionEntry e = sectionEntry(good, kind);
        for (uint64_t cut : {e.offset, e.offset + 1, e.offset + e.count * e.stride / 2, e.offset + e.count * e.stride - 1}) {
            std::string message;
            EXPECT_EQ(openCopy(good, size_t(cut), message), FileStatus::Truncated) << kind << " at " << cut << ": " << message;
        }
    }
}

TEST(RuntimeFormat, ColorEncodingIsSrgbWithLinearAlpha) {
    // The 256 codes survive decode + encode; linear black, white and mid-grey land where the
    // sRGB curve puts them; alpha stays linear; out-of-range and NaN are clamped.
    for (int code = 0; code < 256; ++code) {
        const uint8_t in[4] = {uint8_t(code), uint8_t(255 - code), uint8_t(code / 2), uint8_t(code)};
        float linear[4];
        decodeColorSrgb8(in, linear);
        uint8_t back[4];
        encodeColorSrgb8(linear, back);
        for (int k = 0; k < 4; ++k) EXPECT_EQ(back[k], in[k]) << "code " << code << " channel " << k;
        EXPECT_FLOAT_EQ(linear[3], code / 255.0f);
    }
    const float samples[4] = {0.0f, 1.0f, 0.5f, 0.5f};
    uint8_t out[4];
    encodeColorSrgb8(samples, out);
    EXPECT_EQ(out[0], 0);
    EXPECT_EQ(out[1], 255);
    EXPECT_EQ(out[2], 188);  // sRGB(0.5 linear) = 0.7354
    EXPECT_EQ(out[3], 128);  // alpha is not curved
    const float odd[4] = {-1.0f, 7.0f, std::nanf(""), 2.0f};
    encodeColorSrgb8(odd, out);
    EXPECT_EQ(out[0], 0);
    EXPECT_EQ(out[1], 255);
    EXPECT_EQ(out[2], 0);
    EXPECT_EQ(out[3], 255);
}

TEST(RuntimeFormat, PerObjectLodNodesAreAcceptedAndRoundTrip) {
    const BuildArrays p = makeSyntheticHierarchy(50, 12, 3, 1, 1.0f, 2);
    const std::vector<uint8_t> bytes = writeOrDie(p);
    RuntimeFile file;
    std::string message;
    ASSERT_EQ(RuntimeFile::openMemory(bytes.data(), bytes.size(), file, message), FileStatus::Ok) << message;
    uint32_t lods = 0;
    for (uint32_t i = 0; i < file.nodeCount(); ++i) {
        if (!file.isObjectLod(i)) continue;
        ++lods;
        EXPECT_EQ(file.node(i).level, kObjectLodLevel);
        EXPECT_FALSE(file.isLeaf(i));
        ASSERT_EQ(file.sources(i).size, 1u);
        ASSERT_EQ(file.children(i).size, 1u);
        const uint32_t child = file.children(i)[0];
        EXPECT_TRUE(file.isLeaf(child) || file.isObjectLod(child));
        EXPECT_EQ(file.sources(child)[0], file.sources(i)[0]);
        EXPECT_FALSE(file.isObjectLod(file.node(i).parent) && file.isLeaf(file.node(i).parent));
    }
    EXPECT_EQ(lods, 2u * 50u);
}

// A bundle of level k (kBundleLevelFlag | k) ranks between levels k - 1 and k: accepted
// between them, under another bundle of the same level, and read back as a bundle.
TEST(RuntimeFormat, BundleLevelsAreAcceptedBetweenTheirLevels) {
    BuildArrays p = makeSyntheticHierarchy(200, 7);
    const auto rankOf = [](uint32_t level) { return level == kLeafLevel ? -4 : 2 * int64_t(level); };
    uint32_t bundled = 0;
    for (uint32_t i = 0; i < p.nodes.size(); ++i) {
        NodeRecord& n = p.nodes[i];
        if (n.level == kLeafLevel || n.level >= kMaxAggregateLevel || n.level == 0) continue;
        bool fits = true;  // every child strictly below level - 1/2
        for (uint32_t c = n.firstChild; c < n.firstChild + n.childCount; ++c)
            fits = fits && rankOf(p.nodes[p.childIndices[c]].level) < 2 * int64_t(n.level) - 1;
        if (!fits) continue;
        n.level |= kBundleLevelFlag;
        ++bundled;
    }
    ASSERT_GT(bundled, 0u);
    const std::vector<uint8_t> bytes = writeOrDie(p);
    RuntimeFile file;
    std::string message;
    ASSERT_EQ(RuntimeFile::openMemory(bytes.data(), bytes.size(), file, message), FileStatus::Ok) << message;
    EXPECT_EQ(file.versionMinor(), kFormatMinor);
    uint32_t read = 0;
    for (uint32_t i = 0; i < file.nodeCount(); ++i) {
        EXPECT_EQ(file.isBundle(i), isBundleLevel(p.nodes[i].level));
        read += file.isBundle(i);
    }
    EXPECT_EQ(read, bundled);
    EXPECT_TRUE(isBundleLevel(kBundleLevelFlag | 3));
    EXPECT_FALSE(isBundleLevel(3));
    EXPECT_FALSE(isBundleLevel(kLeafLevel));
    EXPECT_FALSE(isBundleLevel(kBundleLevelFlag | kCoarserLevel));
}

TEST(RuntimeFormat, MisalignedBufferIsRefused) {
    const std::vector<uint8_t> good = writeOrDie(makeSyntheticHierarchy(20, 8));
    std::vector<uint8_t> shifted(good.size() + 16);
    std::memcpy(shifted.data() + 4, good.data(), good.size());
    RuntimeFile file;
    std::string message;
    EXPECT_EQ(RuntimeFile::openMemory(shifted.data() + 4, good.size(), file, message), FileStatus::Misaligned);
    EXPECT_FALSE(file.isOpen());
}

// The contract is views of arrays the caller owns: arrays elsewhere than in a BuildArrays
// (here copies in other vectors) give the same bytes, the file's node records are written as
// given, and a count without data is refused instead of read.
TEST(RuntimeFormat, ParamsAreViewsOfTheCallersArrays) {
    const BuildArrays arrays = makeSyntheticHierarchy(40, 5);
    const std::vector<uint8_t> expected = writeOrDie(arrays);
    const std::vector<NodeRecord> nodes = arrays.nodes;
    const std::vector<float> positions = arrays.positions;
    BuildParams p = arrays.params();
    p.nodes = nodes.data();
    p.positions = positions.data();
    std::vector<uint8_t> bytes;
    std::string error;
    ASSERT_TRUE(writeRuntimeFile(p, bytes, error)) << error;
    EXPECT_EQ(bytes, expected);
    RuntimeFile file;
    std::string message;
    ASSERT_EQ(RuntimeFile::openMemory(bytes.data(), bytes.size(), file, message), FileStatus::Ok) << message;
    ASSERT_EQ(file.nodeCount(), nodes.size());
    for (size_t i = 0; i < nodes.size(); ++i)
        EXPECT_EQ(std::memcmp(&file.node(uint32_t(i)), &nodes[i], sizeof(NodeRecord)), 0) << "node " << i;

    BuildParams missing = arrays.params();
    missing.indices = nullptr;
    EXPECT_FALSE(writeRuntimeFile(missing, bytes, error));
    EXPECT_NE(error.find("count but no data"), std::string::npos) << error;
    EXPECT_TRUE(bytes.empty());
}
